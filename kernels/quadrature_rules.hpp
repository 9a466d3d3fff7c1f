#pragma once
// Symmetric quadrature rules on a triangle (paper eq. 15, MODEL.md section 4):
//   integral over the triangle of f dA  ~=  A * sum_i w_i f(l1_i, l2_i, l3_i),
// with (l1, l2, l3) barycentric coordinates and the weights normalised to sum to 1 (the paper's eq. 16
// writes A/N_Q w_i with weights that sum to N_Q; same rule).
//   n = 1:  centroid, degree 1.
//   n = 3:  (2/3, 1/6, 1/6) and permutations, degree 2 (Strang & Fix).
//   n = 7:  Radon's degree-5 rule (Strang & Fix table 4.1): centroid and two 3-point orbits
//           a = (6 -+ sqrt 15)/21, weights (155 -+ sqrt 15)/1200, centroid 9/40.
//   n = 16: Zhang, Cui & Liu (2009) degree 8, the rule the paper uses (its ref. [35]); the values are
//           shared/data/quadrature/zhang_cui_liu_deg8_16pt.csv, copied here in the same order.
// All points lie inside the triangle and all weights are positive.
// Expectations (tests/test_quadrature.cpp): weights sum to 1; every monomial x^p y^q with p + q <= degree
// is integrated exactly (to 1e-13 relative) on a general triangle and degree + 1 is not; the 16-point
// table equals the CSV to 1e-15.
// Device-callable: local constexpr tables (no statics), no allocation.
#include "core/kokkos_compat.hpp"

namespace dcm {

// The rules that quadrature_point() knows: 1, 3, 7 and 16 points.
KOKKOS_INLINE_FUNCTION constexpr bool quadrature_rule_valid(int n_points) {
  return n_points == 1 || n_points == 3 || n_points == 7 || n_points == 16;
}

// Polynomial degree integrated exactly by the n-point rule; -1 for an unknown rule.
KOKKOS_INLINE_FUNCTION constexpr int quadrature_rule_degree(int n_points) {
  return n_points == 1 ? 1 : n_points == 3 ? 2 : n_points == 7 ? 5 : n_points == 16 ? 8 : -1;
}

// Point i (0 <= i < n_points) of the n-point rule: barycentric coordinates (l1, l2, l3) and weight w
// (weights sum to 1). An unknown rule or an index out of range gives the centroid with weight 0.
KOKKOS_INLINE_FUNCTION void quadrature_point(int n_points, int i, double& l1, double& l2, double& l3,
                                             double& w) {
  l1 = l2 = l3 = 1.0 / 3.0;
  w = 0;
  if (i < 0 || i >= n_points) return;
  switch (n_points) {
    case 1:
      w = 1;
      return;
    case 3: {
      constexpr double a = 2.0 / 3.0, b = 1.0 / 6.0;
      l1 = i == 0 ? a : b;
      l2 = i == 1 ? a : b;
      l3 = i == 2 ? a : b;
      w = 1.0 / 3.0;
      return;
    }
    case 7: {
      if (i == 0) {
        w = 9.0 / 40.0;
        return;
      }
      // orbit (a, a, 1 - 2a) and its permutations; the odd point of the orbit is at position (i-1) % 3
      constexpr double a1 = 0.101286507323456338800987361915, b1 = 0.79742698535308732239802527617;
      constexpr double w1 = 0.1259391805448271525956839455;
      constexpr double a2 = 0.470142064105115089770441209513, b2 = 0.0597158717897698204591175809732;
      constexpr double w2 = 0.132394152788506180737649387833;
      const bool first = i <= 3;
      const double a = first ? a1 : a2, b = first ? b1 : b2;
      const int odd = (i - 1) % 3;
      l1 = odd == 0 ? b : a;
      l2 = odd == 1 ? b : a;
      l3 = odd == 2 ? b : a;
      w = first ? w1 : w2;
      return;
    }
    case 16: {
      // Zhang, Cui & Liu (2009) J Comput Math 27(1):89-96, degree 8; rows L1, L2, L3, w of the CSV
      constexpr double t[16][4] = {
          {0.3333333333333333333333333, 0.3333333333333333333333333, 0.3333333333333333333333333,
           0.1443156076777871682510911},
          {0.1705693077517602066222935, 0.1705693077517602066222935, 0.658861384496479586755413,
           0.1032173705347182502817916},
          {0.1705693077517602066222935, 0.658861384496479586755413, 0.1705693077517602066222935,
           0.1032173705347182502817916},
          {0.658861384496479586755413, 0.1705693077517602066222935, 0.1705693077517602066222935,
           0.1032173705347182502817916},
          {0.05054722831703097545842355, 0.05054722831703097545842355, 0.8989055433659380490831529,
           0.03245849762319808031092593},
          {0.05054722831703097545842355, 0.8989055433659380490831529, 0.05054722831703097545842355,
           0.03245849762319808031092593},
          {0.8989055433659380490831529, 0.05054722831703097545842355, 0.05054722831703097545842355,
           0.03245849762319808031092593},
          {0.4592925882927231560288155, 0.4592925882927231560288155, 0.08141482341455368794236897,
           0.0950916342672846247938961},
          {0.4592925882927231560288155, 0.08141482341455368794236897, 0.4592925882927231560288155,
           0.0950916342672846247938961},
          {0.08141482341455368794236897, 0.4592925882927231560288155, 0.4592925882927231560288155,
           0.0950916342672846247938961},
          {0.008394777409957605337213835, 0.2631128296346381134217858, 0.7284923929554042812410004,
           0.02723031417443499426484469},
          {0.008394777409957605337213835, 0.7284923929554042812410004, 0.2631128296346381134217858,
           0.02723031417443499426484469},
          {0.2631128296346381134217858, 0.008394777409957605337213835, 0.7284923929554042812410004,
           0.02723031417443499426484469},
          {0.2631128296346381134217858, 0.7284923929554042812410004, 0.008394777409957605337213835,
           0.02723031417443499426484469},
          {0.7284923929554042812410004, 0.008394777409957605337213835, 0.2631128296346381134217858,
           0.02723031417443499426484469},
          {0.7284923929554042812410004, 0.2631128296346381134217858, 0.008394777409957605337213835,
           0.02723031417443499426484469},
      };
      l1 = t[i][0];
      l2 = t[i][1];
      l3 = t[i][2];
      w = t[i][3];
      return;
    }
    default:
      return;
  }
}

}  // namespace dcm
