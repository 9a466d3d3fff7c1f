// Triangle quadrature rules (kernels/quadrature_rules.hpp): weights, points, the degree each rule
// integrates exactly (and that it is not exact one degree higher), and the 16-point table against the CSV.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dcm_config.hpp"
#include "kernels/quadrature_rules.hpp"

#ifndef DCM_SOURCE_DIR
#error "DCM_SOURCE_DIR must be defined to the repository root"
#endif

namespace dcm {
namespace {

const int kRules[] = {1, 3, 7, 16};

// A general triangle in the positive quadrant (every monomial is positive on it, so the exact integrals
// have no cancellation and a relative error is meaningful).
constexpr double kX[3] = {0.3, 1.7, 0.6}, kY[3] = {0.2, 0.4, 1.3};

double triangle_area() {
  return 0.5 * std::fabs((kX[1] - kX[0]) * (kY[2] - kY[0]) - (kX[2] - kX[0]) * (kY[1] - kY[0]));
}

long double factorial(int n) {
  long double f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

// Exact integral of x^p y^q over the triangle: x = sum_i l_i x_i, y = sum_i l_i y_i expanded by the
// multinomial theorem, with  integral l1^a l2^b l3^c dA = 2 A a! b! c! / (a + b + c + 2)!.
long double exact_monomial(int p, int q) {
  // coefficients of x^p as a polynomial in (l1, l2, l3): index [a][b], c = p - a - b
  auto expand = [](const double* c3, int n) {
    std::vector<std::vector<long double>> poly(n + 1, std::vector<long double>(n + 1, 0));
    for (int a = 0; a <= n; ++a)
      for (int b = 0; a + b <= n; ++b) {
        const int c = n - a - b;
        poly[a][b] = factorial(n) / (factorial(a) * factorial(b) * factorial(c)) *
                     std::pow((long double)c3[0], a) * std::pow((long double)c3[1], b) *
                     std::pow((long double)c3[2], c);
      }
    return poly;
  };
  const auto px = expand(kX, p), py = expand(kY, q);
  long double sum = 0;
  for (int a1 = 0; a1 <= p; ++a1)
    for (int b1 = 0; a1 + b1 <= p; ++b1)
      for (int a2 = 0; a2 <= q; ++a2)
        for (int b2 = 0; a2 + b2 <= q; ++b2) {
          const int a = a1 + a2, b = b1 + b2, c = (p - a1 - b1) + (q - a2 - b2);
          sum +=
              px[a1][b1] * py[a2][b2] * factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 2);
        }
  return 2 * (long double)triangle_area() * sum;
}

double quadrature_monomial(int n, int p, int q) {
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    double l1, l2, l3, w;
    quadrature_point(n, i, l1, l2, l3, w);
    const double x = l1 * kX[0] + l2 * kX[1] + l3 * kX[2], y = l1 * kY[0] + l2 * kY[1] + l3 * kY[2];
    sum += w * std::pow(x, p) * std::pow(y, q);
  }
  return triangle_area() * sum;
}

// Largest relative error over the monomials of total degree exactly `degree`.
double max_error_at_degree(int n, int degree) {
  double worst = 0;
  for (int p = 0; p <= degree; ++p) {
    const int q = degree - p;
    const long double exact = exact_monomial(p, q);
    worst = std::max(worst, (double)std::fabs((quadrature_monomial(n, p, q) - exact) / exact));
  }
  return worst;
}

TEST(QuadratureRules, WeightsSumToOnePointsInsideTriangle) {
  for (int n : kRules) {
    ASSERT_TRUE(quadrature_rule_valid(n));
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      double l1, l2, l3, w;
      quadrature_point(n, i, l1, l2, l3, w);
      EXPECT_GT(w, 0) << n << "-point rule, point " << i;
      EXPECT_GE(l1, 0);
      EXPECT_GE(l2, 0);
      EXPECT_GE(l3, 0);
      EXPECT_NEAR(l1 + l2 + l3, 1.0, 1e-15) << n << "-point rule, point " << i;
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0, 1e-15) << n << "-point rule";
  }
  for (int n : {0, 2, 4, 6, 12, 17}) EXPECT_FALSE(quadrature_rule_valid(n));
  EXPECT_EQ(quadrature_rule_degree(1), 1);
  EXPECT_EQ(quadrature_rule_degree(3), 2);
  EXPECT_EQ(quadrature_rule_degree(7), 5);
  EXPECT_EQ(quadrature_rule_degree(16), 8);
}

TEST(QuadratureRules, UnknownRuleOrIndexGivesZeroWeight) {
  double l1, l2, l3, w = -1;
  quadrature_point(5, 0, l1, l2, l3, w);
  EXPECT_EQ(w, 0);
  quadrature_point(7, 7, l1, l2, l3, w);
  EXPECT_EQ(w, 0);
  quadrature_point(16, -1, l1, l2, l3, w);
  EXPECT_EQ(w, 0);
}

TEST(QuadratureRules, ExactUpToDegreeNotBeyond) {
  std::printf("  rule   degree   max rel. error (deg <= d)   max rel. error (deg d+1)\n");
  for (int n : kRules) {
    const int d = quadrature_rule_degree(n);
    double exact_worst = 0;
    for (int k = 0; k <= d; ++k) exact_worst = std::max(exact_worst, max_error_at_degree(n, k));
    const double beyond = max_error_at_degree(n, d + 1);
    std::printf("  %4d   %6d   %.2e                    %.2e\n", n, d, exact_worst, beyond);
    EXPECT_LE(exact_worst, 1e-13) << n << "-point rule";
    EXPECT_GT(beyond, 1e-8) << n << "-point rule is exact one degree beyond its claim";
  }
}

TEST(QuadratureRules, SixteenPointTableEqualsCsv) {
  const std::string path = DCM_SOURCE_DIR "/../shared/data/quadrature/zhang_cui_liu_deg8_16pt.csv";
  std::ifstream in(path);
  ASSERT_TRUE(in.good()) << "cannot open " << path;
  std::string line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'L') continue;  // comments and the header
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    ASSERT_EQ(row.size(), 4u) << line;
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), 16u);
  double worst = 0;
  for (int i = 0; i < 16; ++i) {
    double q[4];
    quadrature_point(16, i, q[0], q[1], q[2], q[3]);
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(q[c], rows[i][c], 1e-15) << "row " << i << " column " << c;
      worst = std::max(worst, std::fabs(q[c] - rows[i][c]));
    }
  }
  std::printf("  16-point table vs CSV: max |difference| = %.2e\n", worst);
}

}  // namespace
}  // namespace dcm
