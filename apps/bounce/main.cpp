// bounce: the paper's bouncing-ball test (its Text S2 / Video S3; docs/model/bounce.md). A stiff (rigid)
// triangulated ball with mass falls on the plane under gravity; the contact is the rounded-triangle
// Maugis–Dugdale kernel with W = 0 (Hertz with the paper's geometric contact radius a² = 2Rδ − δ²,
// kernels/plane_contact.hpp), integrated by velocity Verlet with a rotation update by the exponential map.
// The rebound heights of icospheres of several resolutions are compared with those of a perfect sphere
// obeying the same continuum law P(δ) = K a³/R, integrated by RK4 with a tiny step. Writes
// <out>/summary.json, <out>/series.csv (t_s, reference_m: the perfect sphere's, then
// nodes_<N>_m: the height of each ball's lowest point) and <out>/bounce.h5
// + .xmf (the balls and the perfect sphere side by side, --frames-per-bounce frames per bounce: the paper's
// Video S3 in ParaView).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/common/app_cli.hpp"
#include "core/h5_output.hpp"
#include "core/host_mesh.hpp"
#include "core/json_writer.hpp"
#include "core/kokkos_compat.hpp"
#include "core/update_geometry.hpp"
#include "kernels/plane_contact.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;
using Mem = Exec::memory_space;
constexpr double kPi = 3.14159265358979323846;

struct BounceOptions {
  std::vector<int> nodes = {162, 642, 2562, 10242};
  int bounces = 3;
  double drop_height = 1e-3;  // m, of the lowest point (centre height − R) at release
  int quadrature_points = 0;
  double radius = 1e-3;   // m
  double E = 1e6;         // Pa
  double nu = 0.4;        // –
  double density = 1000;  // kg/m³
  double gravity = 9.81;  // m/s²
  double tilt_deg = 20;   // initial rotation of the mesh about the axis (1, 2, 0)/√5
  double steps_per_contact = 2000;
  double reference_steps_per_contact = 2e5;
  int frames_per_bounce = 20;  // frames of bounce.h5 per bounce; 0: no bounce.h5 / .xmf
  std::string out_dir = "out/bounce";
  int threads = 0;
  bool quiet = false;
  bool check = false;  // --check: the options and the output folder only, nothing written or run
};

// ---- small host-side rigid-body algebra ----

struct Mat3 {
  double m[3][3];
};

Mat3 identity() { return {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; }

Real3 mul(const Mat3& a, Real3 v) {
  return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
          a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
          a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}

Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c.m[i][j] += a.m[i][k] * b.m[k][j];
  return c;
}

// exp([θ]×): the rotation by |θ| about θ/|θ| (Rodrigues; series for tiny angles).
Mat3 rotation(Real3 theta) {
  const double angle = norm(theta);
  double s, c1;  // sin(φ)/φ and (1 − cos φ)/φ²
  if (angle < 1e-4) {
    s = 1 - angle * angle / 6;
    c1 = 0.5 - angle * angle / 24;
  } else {
    s = std::sin(angle) / angle;
    c1 = (1 - std::cos(angle)) / (angle * angle);
  }
  const double x = theta.x, y = theta.y, z = theta.z;
  const double K[3][3] = {{0, -z, y}, {z, 0, -x}, {-y, x, 0}};
  Mat3 r = identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double k2 = 0;
      for (int k = 0; k < 3; ++k) k2 += K[i][k] * K[k][j];
      r.m[i][j] += s * K[i][j] + c1 * k2;
    }
  return r;
}

// Gram–Schmidt on the rows, against the drift of many products.
Mat3 orthonormalized(Mat3 a) {
  Real3 r0{a.m[0][0], a.m[0][1], a.m[0][2]}, r1{a.m[1][0], a.m[1][1], a.m[1][2]};
  r0 = (1 / norm(r0)) * r0;
  r1 = r1 - dot(r0, r1) * r0;
  r1 = (1 / norm(r1)) * r1;
  const Real3 r2 = cross(r0, r1);
  return {{{r0.x, r0.y, r0.z}, {r1.x, r1.y, r1.z}, {r2.x, r2.y, r2.z}}};
}

// ---- the trajectory of the lowest point, for series.csv ----

struct Trajectory {
  struct Flight {
    double t0, t1, h0, v0;
  };
  std::vector<double> t, h;  // samples during contact phases
  std::vector<Flight> flights;
  double g = 9.81;
  double end() const {
    return std::max(t.empty() ? 0.0 : t.back(), flights.empty() ? 0.0 : flights.back().t1);
  }
  double at(double time) const {
    for (const Flight& f : flights)
      if (time >= f.t0 && time <= f.t1) {
        const double s = time - f.t0;
        return f.h0 + f.v0 * s - 0.5 * g * s * s;
      }
    const auto it = std::upper_bound(t.begin(), t.end(), time);
    if (it == t.begin() || it == t.end()) return NAN;
    const std::size_t i = static_cast<std::size_t>(it - t.begin());
    const double w = (time - t[i - 1]) / (t[i] - t[i - 1]);
    return (1 - w) * h[i - 1] + w * h[i];
  }
};

// ---- the perfect sphere: m z'' = −m g + P(R − z), RK4 in contact, exact parabolas in flight ----

struct SphereResult {
  std::vector<double> heights;  // of the lowest point at each apex (m)
  double energy_drift = 0;      // max |E_apex − E_0| / E_0
  double max_overlap = 0;       // m
  double contact_time = 0;      // of the first bounce (s)
  long long steps = 0;
  double wall_s = 0;
  Trajectory traj;
};

SphereResult perfect_sphere(const BounceOptions& o, const MdMaterial& mat, double mass, double dt) {
  const auto wall0 = std::chrono::steady_clock::now();
  const double R = o.radius, g = o.gravity;
  SphereResult r;
  r.traj.g = g;
  auto accel = [&](double z) { return -g + md_state_from_overlap(R - z, R, mat).P / mass; };
  double t = 0, z = R + o.drop_height, v = 0;
  const double e0 = g * o.drop_height;  // per unit mass, relative to z = R
  for (int b = 0; b < o.bounces; ++b) {
    // Flight down to the touch z = R.
    const double tf = (v + std::sqrt(v * v + 2 * g * (z - R))) / g;
    r.traj.flights.push_back({t, t + tf, z - R, v});
    t += tf;
    v -= g * tf;
    z = R;
    const double t_touch = t;
    r.traj.t.push_back(t);
    r.traj.h.push_back(0);
    do {
      const double k1z = v, k1v = accel(z);
      const double k2z = v + 0.5 * dt * k1v, k2v = accel(z + 0.5 * dt * k1z);
      const double k3z = v + 0.5 * dt * k2v, k3v = accel(z + 0.5 * dt * k2z);
      const double k4z = v + dt * k3v, k4v = accel(z + dt * k3z);
      z += dt / 6 * (k1z + 2 * k2z + 2 * k3z + k4z);
      v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      t += dt;
      ++r.steps;
      r.max_overlap = std::max(r.max_overlap, R - z);
      r.traj.t.push_back(t);
      r.traj.h.push_back(z - R);
      if (r.steps > 1000000000LL) throw NumericalError("perfect sphere: no rebound after 1e9 steps");
    } while (!(z > R && v > 0));
    if (b == 0) r.contact_time = t - t_touch;
    // Flight up to the apex.
    const double tu = v / g;
    r.traj.flights.push_back({t, t + tu, z - R, v});
    t += tu;
    z += 0.5 * v * v / g;
    v = 0;
    r.heights.push_back(z - R);
    r.energy_drift = std::max(r.energy_drift, std::fabs(g * (z - R) - e0) / e0);
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

// ---- the triangulated ball: a rigid body whose contact forces come from the rounded-triangle kernel ----

class RigidBall {
 public:
  RigidBall(int subdivisions, double R, const PlaneContactParams& prm)
      : R_(R),
        h_min_(1e-3 / R),
        prm_(prm),
        mesh_(upload_cells<Mem>({HostCell(make_icosphere(subdivisions, R))})),
        geo_(mesh_),
        contact_(mesh_.n_tris),
        body_("dcm::bounce::body", mesh_.n_nodes),
        force_("dcm::bounce::force", mesh_.n_nodes) {
    Kokkos::deep_copy(body_, mesh_.x);
    force_host_ = Kokkos::create_mirror_view(force_);
    const auto b = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), body_);
    body_host_.resize(mesh_.n_nodes);
    for (int i = 0; i < mesh_.n_nodes; ++i) body_host_[i] = {b(i, 0), b(i, 1), b(i, 2)};
    // How far any triangle's sphere reaches from the centre: no contact while the centre is higher.
    update_geometry(Exec(), mesh_, geo_, h_min_);
    const auto c = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), geo_.tri_sphere_center);
    const auto r = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), geo_.tri_sphere_radius);
    for (int t = 0; t < mesh_.n_tris; ++t)
      reach_ = std::max(reach_, std::sqrt(c(t, 0) * c(t, 0) + c(t, 1) * c(t, 1) + c(t, 2) * c(t, 2)) + r(t));
  }

  int n_nodes() const { return mesh_.n_nodes; }
  double reach() const { return reach_; }

  // Contact force and torque about the centre for the ball at centre c, orientation Q (body → world).
  void contact(Real3 centre, const Mat3& Q, Real3& force, Real3& torque) {
    const Exec space;
    const auto x = mesh_.x;
    const auto body = body_;
    const Mat3 q = Q;
    Kokkos::parallel_for(
        "dcm::bounce::place", Kokkos::RangePolicy<Exec>(space, 0, mesh_.n_nodes), KOKKOS_LAMBDA(const int i) {
          const double b0 = body(i, 0), b1 = body(i, 1), b2 = body(i, 2);
          for (int d = 0; d < 3; ++d)
            x(i, d) = (d == 0   ? centre.x
                       : d == 1 ? centre.y
                                : centre.z) +
                      q.m[d][0] * b0 + q.m[d][1] * b1 + q.m[d][2] * b2;
        });
    update_geometry(space, mesh_, geo_, h_min_);
    compute_plane_contact(space, mesh_, geo_, Plane{}, prm_, contact_);
    Kokkos::deep_copy(space, force_, 0.0);
    add_plane_contact_forces(space, mesh_, Plane{}, contact_, force_);
    Kokkos::deep_copy(space, force_host_, force_);
    space.fence();
    force = {0, 0, 0};
    torque = {0, 0, 0};
    for (int i = 0; i < mesh_.n_nodes; ++i) {
      const Real3 f{force_host_(i, 0), force_host_(i, 1), force_host_(i, 2)};
      if (f.x == 0 && f.y == 0 && f.z == 0) continue;
      force += f;
      torque += cross(mul(Q, body_host_[i]), f);
    }
  }

 private:
  double R_, h_min_;
  PlaneContactParams prm_;
  MeshBuffers<Mem> mesh_;
  GeometryBuffers<Mem> geo_;
  ContactBuffers<Mem> contact_;
  Kokkos::View<double*[3], Kokkos::LayoutRight, Mem> body_, force_;
  HostMirrorOf<Kokkos::View<double* [3], Kokkos::LayoutRight, Mem>> force_host_;
  std::vector<Real3> body_host_;
  double reach_ = 0;
};

// A ball's rigid-body state at time t (for the frames of bounce.h5).
struct BallState {
  double t;
  Real3 c, v, w;
  Mat3 Q;
};

struct BallResult {
  int nodes = 0;
  int subdivisions = 0;
  std::vector<double> heights;       // lowest point (centre height − R) at each apex (m)
  std::vector<double> spin;          // |ω| after each bounce (rad/s)
  std::vector<double> energy_error;  // (E_apex − E_0) / E_0 with E = m g (z − R) + ½ I ω², per bounce
  double rotational_fraction = 0;    // ½ I ω² / E_0 after the last bounce
  double reach = 0;                  // max over triangles of |O_t − centre| + R_t (m)
  double contact_time = 0;           // of the first bounce: the span of steps with a contact force (s)
  double max_overlap = 0;            // max of R − centre height (m)
  long long steps = 0;
  double wall_s = 0;
  Trajectory traj;
  std::vector<BallState> states;  // at the start, at every flight's start and after every contact step
};

BallResult triangulated_ball(const BounceOptions& o, const PlaneContactParams& prm, int subdivisions,
                             double mass, double dt) {
  const auto wall0 = std::chrono::steady_clock::now();
  const double R = o.radius, g = o.gravity, inertia = 0.4 * mass * R * R;
  RigidBall ball(subdivisions, R, prm);
  BallResult res;
  res.nodes = ball.n_nodes();
  res.subdivisions = subdivisions;
  res.reach = ball.reach();
  res.traj.g = g;
  // Contact is possible only while the centre is below reach; the stepping starts a little above that, and a
  // bounce ends when the centre rises past the same height: a margin below the rebound's apex (≈ R + H), so
  // that a small drop height ends its bounce too (validate(): H ≥ 1e-4 R, reach − R ≤ 2.5e-6 R).
  const double z_enter = ball.reach() + std::min(0.01 * R, 0.5 * o.drop_height);
  const double tilt = o.tilt_deg * kPi / 180;
  Mat3 Q = rotation({tilt / std::sqrt(5.0), 2 * tilt / std::sqrt(5.0), 0});
  Real3 c{0, 0, R + o.drop_height}, v{0, 0, 0}, w{0, 0, 0};
  double t = 0;
  const double e0 = mass * g * o.drop_height;
  const Real3 gravity{0, 0, -mass * g};
  auto record = [&] { res.states.push_back({t, c, v, w, Q}); };
  auto ballistic = [&](double s) {  // exact free flight over time s
    record();
    c = c + s * v + Real3{0, 0, -0.5 * g * s * s};
    v = v + Real3{0, 0, -g * s};
    Q = orthonormalized(mul(rotation(s * w), Q));
    t += s;
  };
  record();
  for (int b = 0; b < o.bounces; ++b) {
    if (c.z > z_enter) {
      const double tf = (v.z + std::sqrt(v.z * v.z + 2 * g * (c.z - z_enter))) / g;
      res.traj.flights.push_back({t, t + tf, c.z - R, v.z});
      ballistic(tf);
    }
    Real3 f, tau;
    ball.contact(c, Q, f, tau);
    f += gravity;
    res.traj.t.push_back(t);
    res.traj.h.push_back(c.z - R);
    const long long max_steps = res.steps + static_cast<long long>(200 * o.steps_per_contact);
    double t_on = -1, t_off = -1;
    do {  // velocity Verlet; rotation: ω half step, exponential map, ω half step (isotropic inertia)
      v = v + (0.5 * dt / mass) * f;
      w = w + (0.5 * dt / inertia) * tau;
      c = c + dt * v;
      Q = orthonormalized(mul(rotation(dt * w), Q));
      ball.contact(c, Q, f, tau);
      t += dt;
      if (f.z > 0) {
        if (t_on < 0) t_on = t;
        t_off = t;
      }
      f += gravity;
      v = v + (0.5 * dt / mass) * f;
      w = w + (0.5 * dt / inertia) * tau;
      ++res.steps;
      res.max_overlap = std::max(res.max_overlap, R - c.z);
      res.traj.t.push_back(t);
      res.traj.h.push_back(c.z - R);
      record();
      if (!std::isfinite(c.z) || !std::isfinite(norm(w)))
        throw NumericalError("ball with " + std::to_string(res.nodes) +
                             " nodes: non-finite state at t = " + detail::format_real(t) + " s");
      if (res.steps > max_steps)
        throw NumericalError("ball with " + std::to_string(res.nodes) + " nodes: no rebound after " +
                             std::to_string(max_steps) + " steps in bounce " + std::to_string(b + 1));
    } while (!(c.z > z_enter && v.z > 0));
    if (b == 0) res.contact_time = t_off - t_on + dt;
    const double tu = v.z / g;
    res.traj.flights.push_back({t, t + tu, c.z - R, v.z});
    ballistic(tu);
    const double e_rot = 0.5 * inertia * norm2(w);
    res.heights.push_back(c.z - R);
    res.spin.push_back(norm(w));
    res.energy_error.push_back((mass * g * (c.z - R) + 0.5 * mass * norm2(v) + e_rot - e0) / e0);
    res.rotational_fraction = e_rot / e0;
  }
  record();
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

// The ball's centre and orientation at time (from the last recorded state before it, moved by the exact free
// flight: exact in flight, within one contact step of the integrator during contact).
void pose_at(const std::vector<BallState>& states, double g, double time, Real3& c, Mat3& Q) {
  auto it = std::upper_bound(states.begin(), states.end(), time,
                             [](double value, const BallState& s) { return value < s.t; });
  const BallState& s = it == states.begin() ? states.front() : *(it - 1);
  const double h = std::max(0.0, time - s.t);
  c = s.c + h * s.v + Real3{0, 0, -0.5 * g * h * h};
  Q = orthonormalized(mul(rotation(h * s.w), s.Q));
}

// bounce.h5 + .xmf: the perfect sphere (drawn as a 642-node icosphere; it does not rotate) and each
// triangulated ball side by side along x, 2.5 R apart; /mesh/node_cell says which object a node belongs to
// (0 the perfect sphere, then the balls in the order of --nodes); frames on a uniform grid over [0, t_end];
// /series as series.csv.
void write_frames(const std::string& path, const BounceOptions& o, const SphereResult& ref,
                  const std::vector<BallResult>& balls, double t_end,
                  const std::vector<std::vector<std::pair<std::string, double>>>& series) {
  const double R = o.radius;
  std::vector<HostMesh> shapes{make_icosphere(3, R)};
  for (const BallResult& b : balls) shapes.push_back(make_icosphere(b.subdivisions, R));
  std::vector<double> x0;
  std::vector<int> tri, cell;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    const int base = static_cast<int>(x0.size() / 3);
    for (const auto& p : shapes[k].nodes) {
      x0.insert(x0.end(), {p[0] + 2.5 * R * static_cast<double>(k), p[1], p[2] + R + o.drop_height});
      cell.push_back(static_cast<int>(k));
    }
    for (const auto& t : shapes[k].triangles) tri.insert(tri.end(), {base + t[0], base + t[1], base + t[2]});
  }
  H5Output h5(path);
  h5.write_text("app", "bounce");
  h5.write_scalar("radius_m", R);
  h5.write_scalar("drop_height_m", o.drop_height);
  h5.write_mesh(x0.data(), static_cast<int>(cell.size()), tri.data(), static_cast<int>(tri.size() / 3),
                cell.data());
  const int n_frames = o.frames_per_bounce * o.bounces;
  std::vector<double> x(x0.size());
  for (int f = 0; f <= n_frames; ++f) {
    const double time = t_end * f / n_frames;
    std::size_t i = 0;
    const double z = ref.traj.at(time) + R;  // the perfect sphere: its lowest point's height, no rotation
    for (const auto& p : shapes[0].nodes) {
      x[i++] = p[0];
      x[i++] = p[1];
      x[i++] = p[2] + z;
    }
    for (std::size_t k = 1; k < shapes.size(); ++k) {
      Real3 c;
      Mat3 Q;
      pose_at(balls[k - 1].states, o.gravity, time, c, Q);
      for (const auto& p : shapes[k].nodes) {
        const Real3 r = mul(Q, Real3{p[0], p[1], p[2]});
        x[i++] = c.x + r.x + 2.5 * R * static_cast<double>(k);
        x[i++] = c.y + r.y;
        x[i++] = c.z + r.z;
      }
    }
    h5.write_frame(time, x.data(), {});
  }
  for (const auto& row : series) h5.append_series(row);
  h5.close();
}

// ---- options ----

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void require(bool ok, const std::string& option, double value, const std::string& allowed) {
  if (!ok)
    throw SceneError(option + " = " + detail::format_real(value) + " is out of range (allowed " + allowed +
                     ")");
}

int subdivisions_for(int nodes) {
  for (int k = 0; k <= 6; ++k)
    if (icosphere_node_count(k) == nodes) return k;
  return -1;
}

// Hertz contact time of the law P = k δ^{3/2}, k = K (2R)^{3/2} / R (the geometric a² ≈ 2Rδ), at impact
// speed v: t_c = 2.9432 δ_max / v, δ_max = (5 m v² / (4 k))^{2/5}.
double hertz_contact_time(double K, double R, double mass, double v, double& delta_max) {
  const double k = K * std::pow(2 * R, 1.5) / R;
  delta_max = std::pow(5 * mass * v * v / (4 * k), 0.4);
  return 2.9432 * delta_max / v;
}

void validate(const BounceOptions& o) {
  require(!o.nodes.empty(), "--nodes", 0, "one or more icosphere node counts");
  for (std::size_t k = 0; k < o.nodes.size(); ++k) {
    require(subdivisions_for(o.nodes[k]) >= 0, "--nodes", o.nodes[k],
            "icosphere node counts 12, 42, 162, 642, 2562, 10242, 40962");
    for (std::size_t j = 0; j < k; ++j)
      require(o.nodes[j] != o.nodes[k], "--nodes", o.nodes[k], "each node count once");
  }
  require(o.bounces >= 1 && o.bounces <= 20, "--bounces", o.bounces, "1 .. 20");
  require(o.quadrature_points == 0 || o.quadrature_points == 1 || o.quadrature_points == 3 ||
              o.quadrature_points == 7 || o.quadrature_points == 16,
          "--quadrature-points", o.quadrature_points, "0 (exact polar integration), 1, 3, 7 or 16");
  require(o.radius > 0 && o.radius <= 1, "--radius-m", o.radius, "0 < R <= 1 m");
  require(o.E > 0 && std::isfinite(o.E), "--E", o.E, "0 < E, Pa");
  require(o.nu >= 0 && o.nu < 0.5, "--nu", o.nu, "0 <= nu < 0.5");
  require(o.density > 0 && std::isfinite(o.density), "--density", o.density, "0 < density, kg/m^3");
  require(o.gravity > 0 && std::isfinite(o.gravity), "--gravity", o.gravity, "0 < g, m/s^2");
  require(std::fabs(o.tilt_deg) <= 360, "--tilt-deg", o.tilt_deg, "-360 .. 360");
  require(o.steps_per_contact >= 100 && o.steps_per_contact <= 1e6, "--steps-per-contact",
          o.steps_per_contact, "100 .. 1e6");
  require(o.reference_steps_per_contact >= 1000 && o.reference_steps_per_contact <= 1e7,
          "--reference-steps-per-contact", o.reference_steps_per_contact, "1000 .. 1e7");
  require(o.threads >= 0 && o.threads <= 4096, "--threads", o.threads, "0 .. 4096");
  require(o.drop_height > 0 && std::isfinite(o.drop_height), "--drop-height-m", o.drop_height, "0 < H, m");
  require(o.frames_per_bounce >= 0 && o.frames_per_bounce <= 1000 / o.bounces, "--frames-per-bounce",
          o.frames_per_bounce,
          "0 .. " + std::to_string(1000 / o.bounces) + " with --bounces " + std::to_string(o.bounces) +
              ": at most 1000 frames in bounce.h5 (0: none)");
  // The overlap must stay small against R (the law is a small-strain one; a ≤ R/2 keeps the mesh sensible).
  const MdMaterial mat = md_material(o.E, o.nu, 0.0, 20e-9);
  const double mass = 4.0 / 3.0 * kPi * std::pow(o.radius, 3) * o.density;
  double delta_max = 0;
  hertz_contact_time(mat.K, o.radius, mass, std::sqrt(2 * o.gravity * o.drop_height), delta_max);
  // δ_max ∝ H^{2/5}: the largest H with δ_max ≤ 0.1 R.
  const double h_max = o.drop_height * std::pow(0.1 * o.radius / delta_max, 2.5);
  // Below 1e-4 R the rebound would not clear the rounded triangles' reach above R by a safe margin (reach − R
  // is up to 2.5e-6 R: 162 nodes, docs/model/bounce.md) and a bounce could not be told from resting contact.
  const std::string range = num(1e-4 * o.radius) + " <= H <= " + num(h_max) +
                            " m: from 1e-4 R to where the overlap reaches R/10 for these material and ball";
  require(delta_max <= 0.1 * o.radius && o.drop_height >= (1 - 1e-12) * 1e-4 * o.radius, "--drop-height-m",
          o.drop_height, range);
}

// ---- the run ----

void run(const BounceOptions& o) {
  validate(o);
  if (o.check) {
    check_output_dir(o.out_dir);
    if (!o.quiet) std::printf("bounce: ok (checked, nothing written)\n");
    return;
  }
  const std::string out =
      prepare_output_dir(AppOptions{"", {}, o.out_dir, o.threads, o.quiet}, Scene::defaults());
  remove_earlier_outputs(out, {"series.csv", "series.csv.tmp", "summary.json", "bounce.h5", "bounce.xmf"});
  KokkosSession kokkos(o.threads);
  const double R = o.radius;
  PlaneContactParams prm;
  prm.material = md_material(o.E, o.nu, 0.0, 20e-9);  // W = 0: Hertz only (h0 unused but must be > 0)
  prm.quadrature_points = o.quadrature_points;
  const double mass = 4.0 / 3.0 * kPi * R * R * R * o.density;
  const double v_impact = std::sqrt(2 * o.gravity * o.drop_height);
  double delta_max = 0;
  const double t_contact = hertz_contact_time(prm.material.K, R, mass, v_impact, delta_max);
  const double dt = t_contact / o.steps_per_contact;
  const double a_max = std::sqrt(2 * R * delta_max - delta_max * delta_max);
  if (!o.quiet)
    std::printf(
        "dcm bounce: R = %g m, E = %g Pa, nu = %g, rho = %g kg/m^3, g = %g m/s^2, drop height %g m, m = %.4g "
        "kg\n"
        "  impact speed %.4g m/s, Hertz contact time %.4g s, max overlap %.3g m (a_max/R = %.3f), dt = %.3g "
        "s, "
        "quadrature %d; %s\n",
        R, o.E, o.nu, o.density, o.gravity, o.drop_height, mass, v_impact, t_contact, delta_max, a_max / R,
        dt, o.quadrature_points, kokkos_description().c_str());

  const SphereResult ref = perfect_sphere(o, prm.material, mass, t_contact / o.reference_steps_per_contact);
  std::vector<BallResult> balls;
  for (int n : o.nodes) {
    balls.push_back(triangulated_ball(o, prm, subdivisions_for(n), mass, dt));
    if (!o.quiet)
      std::printf("  %5d nodes done in %.2f s (%lld steps)\n", n, balls.back().wall_s, balls.back().steps);
  }

  // Table.
  if (!o.quiet) {
    std::printf("\n%-10s", "ball");
    for (int b = 0; b < o.bounces; ++b) std::printf("  h%-d (m)        rel.err ", b + 1);
    std::printf("  spin (rad/s)  E_rot/E0   t_contact (s)  max overlap (m)  wall (s)\n");
    std::printf("%-10s", "perfect");
    for (double h : ref.heights) std::printf("  %.9e  %8s", h, "");
    std::printf("  %12s  %9s  %13.6e  %15.6e  %8.2f\n", "0", "0", ref.contact_time, ref.max_overlap,
                ref.wall_s);
    for (const BallResult& r : balls) {
      std::printf("%-10s", (std::to_string(r.nodes) + " n").c_str());
      for (std::size_t b = 0; b < r.heights.size(); ++b)
        std::printf("  %.9e  %+8.1e", r.heights[b], r.heights[b] / ref.heights[b] - 1);
      std::printf("  %12.4g  %9.2e  %13.6e  %15.6e  %8.2f\n", r.spin.back(), r.rotational_fraction,
                  r.contact_time, r.max_overlap, r.wall_s);
    }
    std::printf(
        "perfect sphere: energy drift %.2e, contact time %.5g s (Hertz estimate %.5g s), max overlap %.5g "
        "m\n",
        ref.energy_drift, ref.contact_time, t_contact, ref.max_overlap);
  }

  // series.csv on a common grid up to the earliest end.
  double t_end = ref.traj.end();
  for (const BallResult& r : balls) t_end = std::min(t_end, r.traj.end());
  // The rows once, for series.csv and bounce.h5's /series.
  std::vector<std::vector<std::pair<std::string, double>>> series;
  const int n_rows = 2000;
  for (int i = 0; i <= n_rows; ++i) {
    const double time = t_end * i / n_rows;
    series.push_back({{"t_s", time}, {"reference_m", ref.traj.at(time)}});
    for (const BallResult& r : balls)
      series.back().push_back({"nodes_" + std::to_string(r.nodes) + "_m", r.traj.at(time)});
  }
  {
    std::ofstream csv(out + "/series.csv.tmp");
    for (std::size_t k = 0; k < series.front().size(); ++k) csv << (k ? "," : "") << series.front()[k].first;
    csv << '\n';
    char buf[64];
    for (const auto& row : series) {
      for (std::size_t k = 0; k < row.size(); ++k) {
        std::snprintf(buf, sizeof buf, "%s%.9g", k ? "," : "", row[k].second);
        csv << buf;
      }
      csv << '\n';
    }
    if (!csv) throw IoError(out + "/series.csv: cannot write file");
  }
  if (std::rename((out + "/series.csv.tmp").c_str(), (out + "/series.csv").c_str()) != 0)
    throw IoError(out + "/series.csv: cannot write file");

  JsonObject json;
  std::vector<double> nodes;
  std::vector<std::vector<double>> heights, errors, spin, energy;
  std::vector<double> wall, steps, rot, reach, tc, overlap;
  double worst = 0;
  for (const BallResult& r : balls) {
    nodes.push_back(r.nodes);
    heights.push_back(r.heights);
    std::vector<double> e;
    for (std::size_t b = 0; b < r.heights.size(); ++b) {
      e.push_back(r.heights[b] / ref.heights[b] - 1);
      worst = std::max(worst, std::fabs(e.back()));
    }
    errors.push_back(e);
    spin.push_back(r.spin);
    energy.push_back(r.energy_error);
    wall.push_back(r.wall_s);
    steps.push_back(static_cast<double>(r.steps));
    rot.push_back(r.rotational_fraction);
    reach.push_back(r.reach);
    tc.push_back(r.contact_time);
    overlap.push_back(r.max_overlap);
  }
  json.add("nodes", nodes)
      .add("rebound_heights_m", heights)
      .add("reference_rebound_heights_m", ref.heights)
      .add("relative_errors", errors)
      .add("max_relative_error", worst)
      .add("spin_rad_per_s", spin)
      .add("rotational_energy_fraction", rot)
      .add("energy_errors", energy)
      .add("contact_time_s", tc)
      .add("max_overlap_m", overlap)
      .add("reference_energy_drift", ref.energy_drift)
      .add("reference_contact_time_s", ref.contact_time)
      .add("reference_max_overlap_m", ref.max_overlap)
      .add("reference_wall_s", ref.wall_s)
      .add("hertz_contact_time_s", t_contact)
      .add("dt_s", dt)
      .add("steps_per_contact", o.steps_per_contact)
      .add("contact_steps", steps)
      .add("wall_s", wall)  // per mesh; wall_s like every app's summary
      .add("sphere_reach_m", reach)
      .add("radius_m", R)
      .add("E_Pa", o.E)
      .add("nu", o.nu)
      .add("density_kg_m3", o.density)
      .add("gravity_m_s2", o.gravity)
      .add("drop_height_m", o.drop_height)
      .add("mass_kg", mass)
      .add("tilt_deg", o.tilt_deg)
      .add("quadrature_points", o.quadrature_points)
      .add("backend", kokkos_description());
  if (o.frames_per_bounce > 0) write_frames(out + "/bounce.h5", o, ref, balls, t_end, series);
  json.write(out + "/summary.json");
  if (!o.quiet)
    std::printf(
        "wrote %s/summary.json, %s/series.csv%s\n", out.c_str(), out.c_str(),
        o.frames_per_bounce > 0 ? (" and " + out + "/bounce.h5 (+ .xmf: open in ParaView)").c_str() : "");
}

}  // namespace
}  // namespace dcm

int main(int argc, char** argv) {
  dcm::BounceOptions o;
  CLI::App app(
      "bounce: the paper's bouncing-ball test (Text S2 / Video S3). A rigid triangulated ball (icosphere of\n"
      "radius R, uniform density) falls on the plane; contact is the rounded-triangle Hertz law (W = 0) of\n"
      "kernels/plane_contact.hpp. Its rebound heights (lowest point = centre height - R, at each apex) are\n"
      "compared with those of a perfect sphere obeying the same continuum law P = K a^3/R, a^2 = 2 R d - "
      "d^2.\n"
      "Writes <out>/summary.json, <out>/series.csv and <out>/bounce.h5 + bounce.xmf (the balls and the\n"
      "perfect sphere side by side, for ParaView). Model: docs/model/bounce.md",
      "bounce");
  app.footer(
      "Examples:\n  bounce\n  bounce --nodes 162,642 --bounces 1 --out /tmp/b --quiet\n"
      "Exit codes: 0 success, 2 bad input (one line on stderr, nothing written), 3 numerical failure, 1 "
      "internal error.");
  dcm::one_value_per_use(
      app.add_option(
             "--nodes", o.nodes,
             "Icosphere node counts to compare, comma-separated (12, 42, 162, 642, 2562, 10242, 40962)")
          ->type_name("N1,N2,...")
          ->delimiter(','))
      ->capture_default_str();
  app.add_option("--bounces", o.bounces, "Number of bounces, 1 .. 20")->capture_default_str();
  app.add_option(
         "--drop-height-m", o.drop_height,
         "Initial height of the lowest point above the plane (m), at least 1e-4 R, at most the height "
         "whose largest overlap is R/10 (0.138 m for the defaults; a refused value names it)")
      ->capture_default_str();
  app.add_option("--quadrature-points", o.quadrature_points,
                 "Contact integration: 0 exact polar integration, or the paper's 1, 3, 7, 16-point rules")
      ->capture_default_str();
  app.add_option("--radius-m", o.radius, "Ball radius R (m), 0 < R <= 1")->capture_default_str();
  app.add_option("--E", o.E, "Young's modulus (Pa), > 0; K = 4/3 E/(1 - nu^2)")->capture_default_str();
  app.add_option("--nu", o.nu, "Poisson ratio, 0 <= nu < 0.5")->capture_default_str();
  app.add_option("--density", o.density, "Density of the (solid) ball (kg/m^3), > 0")->capture_default_str();
  app.add_option("--gravity", o.gravity, "Gravitational acceleration (m/s^2), > 0")->capture_default_str();
  app.add_option(
         "--tilt-deg", o.tilt_deg,
         "Initial rotation of the mesh about the axis (1, 2, 0)/sqrt(5) (degrees), -360 .. 360; 0 puts a "
         "node at the bottom")
      ->capture_default_str();
  app.add_option("--steps-per-contact", o.steps_per_contact,
                 "Time step of the ball = Hertz contact time / this, 100 .. 1e6")
      ->capture_default_str();
  app.add_option("--reference-steps-per-contact", o.reference_steps_per_contact,
                 "RK4 step of the perfect sphere = Hertz contact time / this, 1000 .. 1e7")
      ->capture_default_str();
  app.add_option("--frames-per-bounce", o.frames_per_bounce,
                 "Frames of bounce.h5/.xmf per bounce, 0 .. 1000 / bounces (0: write no bounce.h5)")
      ->capture_default_str();
  app.add_option("--out", o.out_dir, "Output folder")->capture_default_str();
  app.add_option("--threads", o.threads, "Host threads (0 or not given: OMP_NUM_THREADS, else all cores)");
  app.add_flag("--quiet", o.quiet, "Print only errors");
  app.add_flag(
      "--check", o.check,
      "Only check the options and the output folder (exit 0, or 2 with the error); write and run nothing");
  return dcm::run_app(app, argc, argv, [&] { dcm::run(o); });
}
