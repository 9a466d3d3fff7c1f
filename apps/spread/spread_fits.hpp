#pragma once
// The fits of spread's summary.json (host only): the contact angle from a sphere fitted to the cell's nodes,
// the early exponent of r_cc(t) and how much r_cc still grew at the end. Tested on ideal caps, power laws and
// saturating curves (tests/test_spread_fits.cpp).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace dcm::spread_fits {

// Sphere through a set of nodes (algebraic least squares |x|² = 2 c·x + d); the contact angle from the
// centre's height h_c above the plane: θ = π − acos(h_c / R). Two node sets:
//   paper: the top 95% of the nodes by height (the paper's method). It keeps most of the flat, adhered base
//          (only the lowest 5% of the nodes are dropped, a third of them lie in the contact), which pulls the
//          sphere down and reads the angle too high (tests/test_spread_fits.cpp: ideal caps).
//   free:  the nodes higher than 10% of the cell's height: the free membrane only, the true cap angle.
struct CapFit {
  double radius = NAN, centre_height = NAN, angle_deg = NAN;
};

// x: node positions, 3 per node; plane_z: the plane's height (its normal is +z).
inline CapFit fit_cap(const std::vector<double>& x, double plane_z, bool free_membrane) {
  constexpr double kPi = 3.14159265358979323846;
  const int n = static_cast<int>(x.size() / 3);
  CapFit f;
  if (n < 4) return f;
  std::vector<double> z(n);
  for (int i = 0; i < n; ++i) z[i] = x[3 * i + 2];
  std::vector<double> sorted = z;
  std::sort(sorted.begin(), sorted.end());
  const double cut = free_membrane ? plane_z + 0.1 * (sorted.back() - plane_z)
                                   : sorted[static_cast<std::size_t>(0.05 * (n - 1))];
  Eigen::MatrixXd a(n, 4);
  Eigen::VectorXd b(n);
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (z[i] < cut) continue;
    a.row(m) << 2 * x[3 * i], 2 * x[3 * i + 1], 2 * x[3 * i + 2], 1.0;
    b(m) = x[3 * i] * x[3 * i] + x[3 * i + 1] * x[3 * i + 1] + x[3 * i + 2] * x[3 * i + 2];
    ++m;
  }
  if (m < 4) return f;
  const Eigen::Vector4d s = a.topRows(m).colPivHouseholderQr().solve(b.head(m));
  f.radius = std::sqrt(s(3) + s(0) * s(0) + s(1) * s(1) + s(2) * s(2));
  f.centre_height = s(2) - plane_z;
  f.angle_deg = (kPi - std::acos(std::clamp(f.centre_height / f.radius, -1.0, 1.0))) * 180 / kPi;
  return f;
}

// When the lasting contact began, as the series saw it: the time of the last row without contact (r = 0 or
// NaN) before the last unbroken run of rows with contact, or 0 when that run starts at the first row (a cell
// placed in contact); NaN when no row has contact. The true onset lies between this row and the next. A
// sliver of contact that came and went before (a touch at the mesh's lowest node) does not count.
inline double contact_onset(const std::vector<double>& t, const std::vector<double>& r) {
  std::size_t i = std::min(t.size(), r.size());
  while (i > 0 && !(r[i - 1] > 0)) --i;  // past the rows after the last contact
  if (i == 0) return NAN;
  while (i > 0 && r[i - 1] > 0) --i;  // back to the first row of that run
  return i == 0 ? 0.0 : t[i - 1];
}

// The contact's onset at the resolution of the steps (spread, since session 36). The rows alone place it only
// between two rows (contact_onset above), up to a row interval early: a cell that needs a while to touch down
// (a gap closed under gravity, the Cuvelier set's weak adhesion) then had its first rows after the onset at a
// fraction of that interval from it, and the early exponent moved by ±0.1 with where in the interval the
// onset fell. spread shows the tracker the state at every step's start while the last state it saw had no
// contact (see; the stepper calls that point only with the steps before it accepted, so what it sees is never
// taken back), and every series row it commits (row). Its onset is the start of the step whose end state
// first had contact, in the last unbroken run of rows with contact, the same run contact_onset takes from the
// rows; it is set when that run's first row is committed (and moved once more, inside the same step, by the
// refinement below when that row came before the second state with contact), so contact_onset(rows) ≤ onset
// ≤ that row's time (a contact seen at a step's start and gone before the next row does not count, as in
// contact_onset).
// Since session 38 the onset is placed inside that step: the contact area grows linearly in time as the
// first triangles' spheres press into the plane (a² = 2Rδ, δ growing at the approach speed), so the first two
// states with contact, (t1, A1) and (t2, A2), give t1 − A1 (t2 − t1) / (A2 − A1), clamped to the step
// [t_free, t1]. It matters where the steps before the contact are long: an adaptive run's were 0.77 ms, and
// its early exponent read 0.516 against 0.502 with the paper's 6-µs steps (docs/VALIDATION.md, session 38).
struct OnsetTracker {
  double t_free = 0;        // the last time a state without contact was seen (a step's start or a row)
  double candidate = NAN;   // when the contact the steps see now began (inside the step that made it)
  double onset = NAN;       // the onset of the last run of rows with contact; NaN: no row with contact yet
  bool in_contact = false;  // the last state seen had contact (while not, spread shows it every step's start)
  bool row_contact = false;              // the last row committed had contact
  double t_first = NAN, area_first = 0;  // the first state with contact of the contact seen now
  bool refining = false;                 // that contact's second state is still to come (spread shows it too)

  // The state at time t, the start of a step, has the contact area `area` (0: none).
  void see(double t, double area) {
    if (!(area > 0)) {
      t_free = t;
      in_contact = false;
      refining = false;
    } else if (!in_contact) {
      candidate = t_free;
      in_contact = true;
      t_first = t;
      area_first = area;
      refining = t > t_free;
    } else if (refining && t > t_first) {
      refining = false;
      if (area > area_first) {
        const double t_est = t_first - area_first * (t - t_first) / (area - area_first);
        const double refined = std::min(t_first, std::max(t_free, t_est));
        if (row_contact && onset == candidate) onset = refined;  // the run's first row came before this state
        candidate = refined;
      }
    }
  }
  // A series row at time t: the first row of a run of rows with contact fixes the onset (the step that made
  // the contact: seen at a step's start before, or the row's own step); one without contact ends the run.
  void row(double t, bool contact) {
    if (contact && !row_contact) onset = in_contact ? candidate : t_free;
    if (!contact) {
      in_contact = false;
      refining = false;
      t_free = std::max(t_free, t);
    }
    row_contact = contact;
  }
  // For a checkpoint, whose values are all finite (scripts/check_outputs_finite.py): a time not known yet
  // (NaN) is stored as −1. A checkpoint of sessions 36-37 holds the first five.
  std::vector<double> save() const {
    const auto time = [](double t) { return std::isnan(t) ? -1.0 : t; };
    return {
        t_free,        time(candidate), time(onset),         in_contact ? 1.0 : 0.0, row_contact ? 1.0 : 0.0,
        time(t_first), area_first,      refining ? 1.0 : 0.0};
  }
  void load(const std::vector<double>& v) {
    const auto time = [](double t) { return t < 0 ? NAN : t; };
    t_free = v.at(0);
    candidate = time(v.at(1));
    onset = time(v.at(2));
    in_contact = v.at(3) != 0;
    row_contact = v.at(4) != 0;
    t_first = v.size() >= 8 ? time(v[5]) : NAN;
    area_first = v.size() >= 8 ? v[6] : 0.0;
    refining = v.size() >= 8 && v[7] != 0;
  }
};

// Least-squares slope of log r against log (t − origin) over the rows with from ≤ t − origin ≤ to, t >
// origin and r > 0; NaN with fewer than three such rows or all of them at one time (used says how many there
// were). spread takes origin = the contact's onset: the spreading law r ∝ t^α counts time from it (the
// paper's eq. 2 integrates a da/dt ∝ W/γ_n from a = 0), and so does the window (since session 36; it was the
// run's own time, so an onset inside the window put the first rows after it a fraction of a row interval from
// the origin, where the onset's uncertainty, up to a row interval, moved the slope by ±0.1).
inline double fit_exponent(const std::vector<double>& t, const std::vector<double>& r, double from, double to,
                           int& used, double origin = 0.0) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  used = 0;
  for (std::size_t i = 0; i < t.size() && i < r.size(); ++i) {
    if (t[i] - origin < from || t[i] - origin > to || !(t[i] > origin) || !(r[i] > 0)) continue;
    const double lx = std::log(t[i] - origin), ly = std::log(r[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++used;
  }
  const double spread = used * sxx - sx * sx;  // 0 (up to rounding) when every row has the same t
  if (used < 3 || !(spread > 1e-12 * used * sxx)) return NAN;
  return (used * sxy - sx * sy) / spread;
}

// How much r_cc still grew at the end of a run: (r_last − r(from)) / r_last, r(from) interpolated linearly
// between the rows around t = from (spread: from = 0.9 t_end, the last tenth of the run). NaN when no row
// lies at or before from, none after it, or r_last is not positive. A run whose r_cc saturated gives ~0; a
// run stopped while the cell still spreads as t^α gives 1 − 0.9^α (0.051 for α = 1/2).
inline double final_growth(const std::vector<double>& t, const std::vector<double>& r, double from) {
  const std::size_t n = std::min(t.size(), r.size());
  if (n < 2 || !(r[n - 1] > 0) || !(t[n - 1] > from)) return NAN;
  std::size_t k = n - 1;  // the last row at or before from
  while (k > 0 && t[k] > from) --k;
  if (t[k] > from) return NAN;
  const double w = t[k + 1] > t[k] ? (from - t[k]) / (t[k + 1] - t[k]) : 1.0;
  const double r_from = r[k] + w * (r[k + 1] - r[k]);
  return (r[n - 1] - r_from) / r[n - 1];
}

// Nodes folded into the substrate (session 40): of the nodes below the plane (depth > 0, m), those deeper
// than 3 times their median depth and than h0. A pressed contact holds the bound membrane evenly at a depth
// the law sets (31 nm in the paper's scene, 16 nm with h0 = 1 nm, 0.2 um evenly with W = 0.1 J/m²); membrane
// that buckles or folds over at the rim, where the paper's law pushes back only on triangles facing the
// plane, reaches 10 times that. median: the median depth (0 without nodes below the plane).
inline int folded_nodes(std::vector<double> depth, double h0, double& median) {
  median = 0;
  if (depth.empty()) return 0;
  std::nth_element(depth.begin(), depth.begin() + depth.size() / 2, depth.end());
  median = depth[depth.size() / 2];
  int n = 0;
  for (const double d : depth) n += d > 3 * median && d > h0;
  return n;
}

// The nodes in range of the plane over a run's series rows (within contact.h0_m of it): the most of them a
// row has seen, and the time and r_cc of the first row that saw that many. most = NaN: not known (a run
// continued from a checkpoint of a dcm before session 32).
struct ContactNodes {
  double most = -1, t = NAN, r = NAN;
  void add_row(double nodes, double t_row, double r_row) {
    if (nodes > most) {
      most = nodes;
      t = t_row;
      r = r_row;
    }
  }
  // r_final − r_cc of the first row with the most nodes (m); NaN when not known or without contact then.
  double growth_since(double r_final) const {
    if (!(most > 0) || !(r > 0) || !(r_final > 0)) return NAN;
    return r_final - r;
  }
  // Whether the contact radius moved outward by more than a mesh edge while no more nodes came into range:
  // the contact front then moved past a node ring without binding it, which only in-plane stretching of the
  // membrane already bound does (docs/model/contact_line.md, "The line held at a node ring"). Growth within
  // the triangles of the last ring (the paper's law at rest, a coarse mesh) stays below an edge.
  bool grew_by_stretching(double r_final, double edge_m) const { return growth_since(r_final) > edge_m; }
};

// The mean edge length of a triangle mesh (each edge counted once per triangle: on a closed mesh every edge
// twice, so the mean of the edges).
inline double mean_edge_length(const std::vector<std::array<double, 3>>& x,
                               const std::vector<std::array<int, 3>>& tri) {
  double sum = 0;
  for (const auto& t : tri)
    for (int k = 0; k < 3; ++k) {
      const auto& a = x[t[k]];
      const auto& b = x[t[(k + 1) % 3]];
      sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                       (a[2] - b[2]) * (a[2] - b[2]));
    }
  return tri.empty() ? NAN : sum / (3.0 * static_cast<double>(tri.size()));
}

}  // namespace dcm::spread_fits
