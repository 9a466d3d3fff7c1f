// The scene schema: every run-time key of dcm with type, default, range, unit and documentation.
// Cortex, fluid and contact defaults follow Table 1 of Odenthal, Smeets et al. (2013).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "core/scene.hpp"

namespace dcm {
namespace {

enum class MinBound { Inclusive, Exclusive };

ParamSpec real_key(const std::string& key, const std::string& def, double min, double max, MinBound bound,
                   const std::string& unit, const std::string& doc) {
  ParamSpec s;
  s.key = key;
  s.type = ParamType::Real;
  s.default_value = def;
  s.min = min;
  s.max = max;
  s.has_range = true;
  s.min_exclusive = bound == MinBound::Exclusive;
  s.unit = unit;
  s.doc = doc;
  return s;
}

ParamSpec int_key(const std::string& key, const std::string& def, double min, double max,
                  const std::string& doc) {
  ParamSpec s;
  s.key = key;
  s.type = ParamType::Int;
  s.default_value = def;
  s.min = min;
  s.max = max;
  s.has_range = true;
  s.doc = doc;
  return s;
}

ParamSpec int_choice_key(const std::string& key, const std::string& def, std::vector<std::string> choices,
                         const std::string& doc) {
  ParamSpec s;
  s.key = key;
  s.type = ParamType::Int;
  s.default_value = def;
  s.choices = std::move(choices);
  s.doc = doc;
  return s;
}

ParamSpec string_key(const std::string& key, const std::string& def, std::vector<std::string> choices,
                     const std::string& doc) {
  ParamSpec s;
  s.key = key;
  s.type = ParamType::String;
  s.default_value = def;
  s.choices = std::move(choices);
  s.doc = doc;
  return s;
}

ParamSpec bool_key(const std::string& key, const std::string& def, const std::string& doc) {
  ParamSpec s;
  s.key = key;
  s.type = ParamType::Bool;
  s.default_value = def;
  s.doc = doc;
  return s;
}

constexpr MinBound kIncl = MinBound::Inclusive;
constexpr MinBound kExcl = MinBound::Exclusive;

std::vector<ParamSpec> make_schema() {
  return {
      string_key(
          "name", "", {},
          "run name; output goes to out/<name> unless output.dir is set (empty: the scene file's stem; "
          "without a scene file the app's name: spread, stretch, relax, geometry)"),

      string_key("mesh.shape", "sphere", {"sphere", "evans_fung"},
                 "sphere = icosphere of radius mesh.radius_m; evans_fung = Evans–Fung biconcave RBC of "
                 "diameter mesh.diameter_m"),
      int_key("mesh.subdivisions", "4", 0, 6,
              "icosphere subdivisions: 0..6 give 12, 42, 162, 642, 2562, 10242, 40962 nodes"),
      int_choice_key("mesh.nodes", "2562", {"12", "42", "162", "642", "2562", "10242", "40962"},
                     "node count (10·4^k+2); an alternative to mesh.subdivisions"),
      real_key("mesh.radius_m", "3.25e-6", 0, 1e-3, kExcl, "m", "radius of the sphere"),
      real_key("mesh.diameter_m", "7.82e-6", 0, 1e-3, kExcl, "m", "Evans–Fung diameter D"),
      int_key(
          "mesh.refine_levels", "0", 0, 4,
          "local refinement: the triangles reaching polar angles mesh.refine_from_deg .. mesh.refine_to_deg "
          "(from the lowest point, the one that meets the plane) are split 1-to-4 this many more times, each "
          "level halving the edge there (red-green closure at the border; docs/model/mesh_refinement.md); "
          "0 = none"),
      real_key(
          "mesh.refine_from_deg", "60", 0, 180, kIncl, "deg",
          "where the refined band starts: polar angle from the lowest point of the sphere (of the sphere "
          "mapped to the Evans–Fung shape)"),
      real_key("mesh.refine_to_deg", "100", 0, 180, kIncl, "deg",
               "where the refined band ends (polar angle from the lowest point); above mesh.refine_from_deg"),

      real_key("geometry.h_min_per_m", "1e4", 0, 1e9, kExcl, "1/m",
               "lower clamp of the triangle mean curvature H (the rounded triangles' radius is at most "
               "1/H_min)"),

      real_key("cortex.E_Pa", "800e3", 1, 1e9, kIncl, "Pa", "Young's modulus of the cortex (contact law)"),
      real_key("cortex.nu", "0.4", 0, 0.5, kIncl, "", "Poisson ratio of the cortex"),
      real_key("cortex.k_s_N_per_m", "3.2e-6", 0, 1, kExcl, "N/m", "FENE+POW spring constant"),
      real_key("cortex.x_max", "2.05", 1, 10, kExcl, "", "maximum bond extension d_max/d*"),
      real_key(
          "cortex.bond_prestretch", "1", 1, 10, kIncl, "",
          "initial bond length over its rest length d*: 1 = the cell is given in its rest state (the paper); "
          "> 1 = its network is under tension in the given shape, as a swollen cell's (dcm's extension, "
          "docs/model/contact_line.md); must be below cortex.x_max"),
      real_key(
          "cortex.c_N_s_per_m", "1.5e-6", 0, 1, kIncl, "N·s/m",
          "cortex damping c (Table 1): the membrane's in-plane shear viscosity (N·s/m = Pa·s·m), or each "
          "bond's dashpot coefficient, as cortex.c_reading says"),
      string_key(
          "cortex.c_reading", "surface_viscosity", {"surface_viscosity", "bond"},
          "surface_viscosity: c is the membrane's shear viscosity, Hochmuth's t_c = c/μ; each bond's dashpot "
          "c_b is 4c/√3 (axial; 2c/√3 with cortex.dashpot = relative), the triangular network's lattice "
          "factor (docs/MODEL.md); bond: c_b = c (eq. 25 read literally, as the project's reading guide "
          "writes it; dcm's reading until session 29, relaxation time 0.085-0.09 s against the paper's "
          "0.1-0.3 s)"),
      string_key(
          "cortex.dashpot", "axial", {"axial", "relative"},
          "axial: the bond dashpot c_b (cortex.c_reading) damps the bond-length rate only (eq. 25); "
          "relative: "
          "it damps the whole relative velocity c_b (v_i − v_j), as eq. 32 writes it (also damps bending and "
          "rigid rotation)"),
      real_key("cortex.k_b_J", "240e-21", 0, 1e-15, kIncl, "J", "bending stiffness"),
      real_key("cortex.k_a", "6e-3", 0, 10, kIncl, "N/m",
               "local area constraint, E = Σ k_a (A_t − A_t*)²/(2A_t*); Table 1's 6e3 read in µN/m "
               "(docs/MODEL.md)"),
      real_key("cortex.k_d", "6e-3", 0, 10, kIncl, "N/m",
               "global area constraint, E = k_d (A − A*)²/(2A*); Table 1's 6e3 read in µN/m"),
      real_key("cortex.k_v", "1e4", 0, 1e9, kIncl, "Pa",
               "volume constraint, E = k_v (V − V*)²/(2V*); Table 1's 10e3"),

      real_key("fluid.eta_Pa_s", "0.8e-3", 0, 10, kExcl, "Pa·s", "viscosity of the medium"),
      real_key("body.gravity_m_per_s2", "0", 0, 1e3, kIncl, "m/s²",
               "gravitational acceleration along −z (9.81 to switch gravity on; 0: no gravity term)"),
      real_key("body.density_excess_kg_per_m3", "75", -1e4, 1e4, kIncl, "kg/m³",
               "cell density minus medium density (RBC in plasma ≈ 1100 − 1025)"),

      bool_key("contact.plane", "false",
               "a substrate plane z = contact.plane_z_m with adhesion (contact.law) and substrate friction "
               "(spread: always on, false is refused; stretch and relax refuse true)"),
      real_key("contact.plane_z_m", "0", -1e-3, 1e-3, kIncl, "m", "height of the substrate plane"),
      string_key("contact.law", "maugis_dugdale", {"maugis_dugdale", "derjaguin"},
                 "the adhesion model: maugis_dugdale = the paper's rounded triangles with the Maugis–Dugdale "
                 "pressure (eqs. 3–19); derjaguin = flat triangles with the Derjaguin energy −W per bound "
                 "area and its exact gradient, which adds the in-plane contact-line force (dcm's extension, "
                 "docs/model/contact_line.md)"),
      int_choice_key("contact.quadrature_points", "0", {"0", "1", "3", "7", "16"},
                     "pressure integration over a triangle: 0 = exact in r (dcm's default), 1/3/7/16 = the "
                     "paper's point rules (eq. 18)"),
      string_key("contact.quadrature_area", "projected", {"projected", "triangle"},
                 "the area the point rules' weights multiply (quadrature_points > 0): projected = the "
                 "triangle's area projected on the plane (dcm: the projections tile the plane); triangle = "
                 "the triangle's own area A_t (the paper's eq. 16 read literally: a tilted triangle counts "
                 "1/cos(tilt) times)"),
      real_key("contact.start_gap_m", "10e-9", -1e-6, 1e-5, kIncl, "m",
               "spread: the cell's lowest node starts this far above the plane (below contact.h0_m, or "
               "higher with gravity on: body.gravity_m_per_s2 > 0, body.density_excess_kg_per_m3 > 0 and a "
               "solver.cg_abs_tol_N below the weight's force norm, which the error message gives; negative: "
               "pressed into the plane)"),
      real_key("contact.W_J_per_m2", "1e-3", 0, 1, kIncl, "J/m²", "work of adhesion"),
      real_key("contact.h0_m", "20e-9", 1e-12, 1e-6, kIncl, "m", "range of adhesion (Dugdale)"),
      real_key("contact.gamma_n_N_s_per_m3", "8e9", 0, 1e15, kIncl, "N·s/m³", "normal substrate friction"),
      real_key("contact.gamma_t_N_s_per_m3", "6e9", 0, 1e15, kIncl, "N·s/m³",
               "tangential substrate friction"),
      string_key(
          "contact.friction_zone", "adhesive", {"adhesive", "contact"},
          "where the substrate friction acts on a triangle: adhesive = within r < max(a, c), the contact "
          "and adhesive zone (dcm); contact = within the contact radius a only (the paper's A^C)"),
      string_key("contact.friction_weights", "area", {"area", "lumped", "consistent"},
                 "how a triangle's substrate friction reaches its nodes: area = w_i Γ_t on each node's own "
                 "velocity, w_i the barycentric coordinates of the friction area's centroid (dcm's default "
                 "since session 8: no jump when a triangle's net load passes through zero); lumped = the "
                 "same with w_i the node's share of the contact force (the default of sessions 3-7); "
                 "consistent = β_i β_j Γ_t on the contact point's velocity"),
      real_key(
          "contact.pin_friction_N_s_per_m", "0", 0, 1, kIncl, "N·s/m",
          "extra friction on nodes whose triangles all lie fully in the contact (the paper's pinning; 0: "
          "off)"),
      real_key(
          "contact.crease_radius_m", "0", 0, 1e-6, kIncl, "m",
          "dcm's experiment (session 34): the fillet radius ρ of the membrane leaving the plane; each rim "
          "edge stores W ρ |e| tan(turn/2) per wing, the adhesion a sharp fold loses against the fillet "
          "(kernels/contact_crease.hpp; √(√3 k_b/4W) = 1.02e-8 m for Table 1; 0: off)"),
      real_key(
          "contact.guard_depth_m", "100e-9", 0, 1e-5, kIncl, "m",
          "the substrate guard (dcm's, session 42; kernels/substrate_guard.hpp): nodes deeper than this "
          "below the plane are pushed back (with contact.guard_stiffness_Pa_per_m > 0). Keep it deeper "
          "than the depth at which the contact law holds a bound membrane: about 30 nm for Table 1, 0.2 um "
          "with W = 0.1 J/m²"),
      real_key(
          "contact.guard_stiffness_Pa_per_m", "0", 0, 1e20, kIncl, "Pa/m",
          "the guard's pressure per metre past contact.guard_depth_m; 0: off (the paper's model). 2.5e13 "
          "= 10 W/h0² for Table 1: the Dugdale stress W/h0 at h0/10 past the depth. For membrane that "
          "folds into the substrate where the contact law does not act (spread warns)"),

      real_key(
          "time.dt_s", "6e-6", 0, 1, kExcl, "s",
          "time step (with time.adaptive: the first step); fixed steps land on time.t_end_s, the last one "
          "up to 1.5 dt long"),
      real_key("time.t_end_s", "1.2", 0, 1e6, kExcl, "s",
               "simulated time (spread; relax runs for --duration-s, stretch to equilibrium)"),
      bool_key("time.adaptive", "false",
               "error-controlled time steps (Euler against Heun, docs/model/time_stepping.md); false: the "
               "fixed time.dt_s of the paper (spread; relax always steps with time.dt_s)"),
      real_key("time.error_tol_m", "1e-9", 0, 1e-6, kExcl, "m",
               "adaptive: allowed local position error per step"),
      real_key("time.dt_min_s", "1e-9", 0, 1, kExcl, "s", "adaptive: smallest step"),
      real_key("time.dt_max_s", "1e-3", 0, 1, kExcl, "s", "adaptive: largest step"),
      real_key("time.contact_change", "0.01", 0, 1, kIncl, "",
               "adaptive: largest relative change of the contact area per step (resolves the touch-down, "
               "docs/model/time_stepping.md); 0: off"),

      real_key("solver.cg_abs_tol_N", "1e-14", 0, 1e-6, kIncl, "N",
               "CG stops when the force residual ||F − Γv||₂ is below this (the paper's 1e-14 N) ..."),
      real_key("solver.cg_rel_tol", "0", 0, 0.1, kIncl, "",
               "... or below this fraction of ||F||₂ (the looser of the two wins)"),
      int_key(
          "solver.cg_max_iterations", "20000", 1, 1e7,
          "CG iterations per solve; in spread a solve that reaches it is retried with half the step, up to "
          "6 times; then (in relax at once) the run stops with exit code 3"),
      string_key(
          "solver.preconditioner", "multigrid", {"block_jacobi", "multigrid"},
          "preconditioner of Γ: multigrid (V-cycle on the icosphere hierarchy; block_jacobi where a mesh "
          "has none) or block_jacobi"),
      int_key("solver.mg_sweeps", "2", 1, 16,
              "multigrid: damped block-Jacobi sweeps before and after each coarse correction (ν)"),
      real_key("solver.mg_damping", "0.6", 0, 0.66, kExcl, "",
               "multigrid: the smoother's damping ω (ω λ_max(D⁻¹A) < 2 keeps the V-cycle positive definite, "
               "and λ_max ≤ 3 on the finest level)"),
      int_key("solver.mg_serial_rows", "1024", 0, 1e9,
              "multigrid: coarse levels with at most this many rows (all cells) run on one thread in OpenMP "
              "builds, where a parallel launch costs more than the work it shares; 0 = never (the results "
              "are the same to the bit either way)"),
      string_key(
          "solver.mg_bending", "auto", {"auto", "on", "off"},
          "multigrid: the implicit bending stiffness in the preconditioner (a positive semi-definite "
          "approximation on the bond pattern; the CG's operator stays exact): auto = for each cell in the "
          "steps where its bending is strong against its dashpots, Δt k_b / (h² (c h²/R² + c_t)) ≥ 0.15 "
          "(fine meshes, long adaptive steps; where the dashpots dominate it costs more than it saves)"),
      bool_key(
          "solver.implicit_bending", "true",
          "bending's Gauss–Newton stiffness in the velocity solve: stable at the paper's Δt on fine meshes"),
      bool_key("solver.implicit_bonds", "true",
               "the bonds' axial FENE+POW stiffness Δt k'(d) in the velocity solve: a bond near d_max cannot "
               "overshoot it (the paper's forward Euler: false)"),
      bool_key("solver.implicit_tension", "true",
               "the area terms' tension stiffness (out of the surface) in the velocity solve: a flat, tense "
               "patch of cortex does not spike at the paper's Δt (solvers/tension_stiffness.hpp)"),
      bool_key("solver.precondition_volume", "false",
               "the implicit volume stiffness (rank one per cell) also in the preconditioner, by the "
               "Sherman–Morrison identity (solvers/global_woodbury.hpp): fewer CG iterations with long "
               "steps"),

      string_key("output.dir", "", {}, "output directory (empty: out/<name>)"),
      bool_key("output.hdf5", "true", "write the HDF5 + XDMF output"),
      real_key(
          "output.frame_every_s", "0.05", 0, 1e6, kExcl, "s",
          "simulated time between HDF5 frames (spread also writes t = 0.1, 0.35, 0.9 s and the end; relax "
          "writes a frame every 20 × --sample-every steps)"),
      real_key("output.early_window_from_s", "0.01", 0, 1e6, kExcl, "s",
               "spread: the early power-law fit (summary.json early_exponent) starts this long after the "
               "contact's onset (--early-window-s overrides; the Cuvelier set's slow spreading needs 2 s)"),
      real_key("output.early_window_to_s", "0.1", 0, 1e6, kExcl, "s",
               "spread: ... and ends this long after it (more than output.early_window_from_s)"),
      int_key("output.series_per_decade", "40", 1, 10000,
              "rows of series.csv per decade of simulated time (log-spaced; every step for the first ten)"),
      real_key("output.checkpoint_every_s", "600", 0, 1e7, kIncl, "s",
               "wall-clock time between checkpoints (<out>/checkpoint.h5; also written at the end and on "
               "Ctrl-C); 0: only those two. spread --restart continues from it"),
  };
}

const char* type_name(ParamType t) {
  switch (t) {
    case ParamType::Int:
      return "integer";
    case ParamType::Real:
      return "real";
    case ParamType::Bool:
      return "bool";
    case ParamType::String:
      return "string";
  }
  return "?";
}

std::string section_of(const std::string& key) {
  const auto dot = key.find('.');
  return dot == std::string::npos ? std::string() : key.substr(0, dot);
}

std::string md_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

std::string md_default(const ParamSpec& s) {
  if (s.type == ParamType::String) return "`\"" + s.default_value + "\"`";
  return "`" + s.default_value + "`";
}

std::string md_allowed(const ParamSpec& s) {
  if (s.type == ParamType::Bool) return "true, false";
  if (s.choices.empty() && !s.has_range) return "any";
  return md_escape(detail::allowed_text(s));
}

}  // namespace

namespace detail {

std::string format_real(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  for (int precision : {15, 16, 17}) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

std::string allowed_text(const ParamSpec& s) {
  std::string out;
  if (!s.choices.empty()) {
    for (size_t i = 0; i < s.choices.size(); ++i) out += (i ? ", " : "") + s.choices[i];
    return out;
  }
  if (!s.has_range) return "any value";
  if (s.min_exclusive) return "> " + format_real(s.min) + " and ≤ " + format_real(s.max);
  return format_real(s.min) + " .. " + format_real(s.max);
}

}  // namespace detail

const std::vector<ParamSpec>& scene_schema() {
  static const std::vector<ParamSpec> schema = make_schema();
  return schema;
}

std::string scene_schema_markdown() {
  std::ostringstream os;
  std::string current = "\x01";  // no section yet
  for (const ParamSpec& s : scene_schema()) {
    const std::string section = section_of(s.key);
    if (section != current) {
      current = section;
      os << (os.tellp() > 0 ? "\n" : "") << (section.empty() ? "## Top level" : "## [" + section + "]")
         << "\n\n| key | type | default | allowed | unit | meaning |\n|---|---|---|---|---|---|\n";
    }
    os << "| `" << s.key << "` | " << type_name(s.type) << " | " << md_default(s) << " | " << md_allowed(s)
       << " | " << md_escape(s.unit) << " | " << md_escape(s.doc) << " |\n";
  }
  return os.str();
}

}  // namespace dcm
