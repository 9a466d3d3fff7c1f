// The scene and checks of a spread member, the batch file and the series format (apps/spread/spread_app.hpp).
#include "apps/spread/spread_app.hpp"

namespace dcm {
namespace spread_app {

namespace {

// The scene of a run: from the file and --set, or, for a restart, from its checkpoint with only the keys
// that do not change the physics allowed to change (a longer t_end, output settings).
Scene spread_scene(const AppOptions& options, const SpreadOptions& so, const Checkpoint* restart) {
  if (!restart) {
    Scene scene = load_scene(options, {"name=spread", "contact.plane=true"});
    if (!scene.was_set(
            "contact.plane")) {  // spread's own default, also under a scene file that leaves it out
      scene.set("contact.plane=true");
      scene.validate();
    }
    return scene;
  }
  if (!options.scene_path.empty())
    throw SceneError("--restart " + so.restart +
                     ": a restart takes its scene from the checkpoint; give no "
                     "scene file (change t_end with --set time.t_end_s=...)");
  if (!options.out_dir.empty())
    throw SceneError("--restart " + so.restart + " with --out " + options.out_dir +
                     ": a restart continues in the folder of its checkpoint; give no --out");
  Scene scene = Scene::from_string(restart->text("scene"), so.restart);
  // A checkpoint of sessions 1-28 (its scene has no cortex.c_reading) continues with c per bond, as it ran.
  if (!scene.was_set("cortex.c_reading")) scene.set("cortex.c_reading=bond");
  for (const std::string& set : options.sets) {
    const std::string key = set.substr(0, set.find('='));
    if ((key != "time.t_end_s" && key.rfind("output.", 0) != 0) || key == "output.hdf5" ||
        key == "output.dir")
      throw SceneError(
          "--set " + set +
          " with --restart: only time.t_end_s and output.* (but output.hdf5 and output.dir) may "
          "change on a restart (the rest would not continue the same run; the run continues in its "
          "folder, its spread.h5 continues or stays absent)");
    scene.set(set);
  }
  scene.validate();
  // t_end = the checkpoint's time finishes the run without a step (a run killed between its last checkpoint
  // and its summary: scan resumes such members); an earlier t_end cannot continue it.
  const double t_done = restart->scalar("stepper.t");
  if (scene.get_real("time.t_end_s") < t_done * (1 - 1e-12))
    throw SceneError("time.t_end_s = " + detail::format_real(scene.get_real("time.t_end_s")) +
                     " is not allowed with --restart " + so.restart + ": the checkpoint is at t = " +
                     detail::format_real(t_done) + " s; continue with --set time.t_end_s=<a later time>");
  return scene;
}

// Splits a member line into words: "double quotes" keep spaces, a backslash takes the next character as it
// is (\" and \\ in a word), and # at the start of a word outside quotes begins a comment.
std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> words;
  std::string w;
  bool quoted = false, have = false;
  for (std::size_t k = 0; k < line.size(); ++k) {
    const char ch = line[k];
    if (ch == '\\') {
      if (k + 1 == line.size()) throw SceneError("a \\ at the end of: " + line);
      w += line[++k];
      have = true;
    } else if (ch == '"') {
      quoted = !quoted;
      have = true;
    } else if (!quoted && !have && ch == '#') {
      break;
    } else if (!quoted && (ch == ' ' || ch == '\t' || ch == '\r')) {
      if (have) words.push_back(w);
      w.clear();
      have = false;
    } else {
      w += ch;
      have = true;
    }
  }
  if (quoted) throw SceneError("an unclosed \" in: " + line);
  if (have) words.push_back(w);
  return words;
}

}  // namespace

std::string series_header() {
  std::string h;
  for (const std::string& c : kSeriesColumns) h += (h.empty() ? "" : ",") + c;
  return h + "\n";
}

std::vector<double> parse_series_rows(const std::string& csv_text) {
  std::vector<double> rows;
  std::size_t pos = csv_text.find('\n');
  while (pos != std::string::npos && pos + 1 < csv_text.size()) {
    const std::size_t end = csv_text.find('\n', pos + 1);
    const std::string line = csv_text.substr(pos + 1, end == std::string::npos ? end : end - pos - 1);
    const char* c = line.c_str();
    for (std::size_t k = 0; k < kSeriesColumns.size(); ++k) {
      char* next = nullptr;
      rows.push_back(std::strtod(c, &next));
      c = *next == ',' ? next + 1 : next;
    }
    pos = end;
  }
  return rows;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The window of the early power-law fit: --early-window-s, else the scene's output.early_window_from_s and
// output.early_window_to_s (a checkpoint of sessions 28-37, whose scene has no such keys, keeps the window
// its run used, stored as app.early_window_s). The window is written into the scene, so that the checkpoint
// and spread.h5 carry the one the run used and a restart keeps it.
static void set_early_window(Member& m) {
  SpreadOptions& so = m.so;
  Scene& scene = m.scene;
  const char* from_key = "output.early_window_from_s";
  const char* to_key = "output.early_window_to_s";
  if (so.early_window_given) {
    if (!(so.early_from_s > 0 && so.early_to_s > so.early_from_s && so.early_to_s <= 1e6))
      throw SceneError("--early-window-s = " + detail::format_real(so.early_from_s) + "," +
                       detail::format_real(so.early_to_s) + " is not allowed: need 0 < from < to <= 1e6 (s)");
    scene.set(std::string(from_key) + "=" + detail::format_real(so.early_from_s));
    scene.set(std::string(to_key) + "=" + detail::format_real(so.early_to_s));
  } else if (m.restart && m.restart->arrays.count("app.early_window_s")) {
    // a checkpoint's scene without the keys (sessions 28-37): each key not given by --set is the run's own
    const std::vector<double>& w = m.restart->array("app.early_window_s", 2);
    if (!scene.was_set(from_key)) scene.set(std::string(from_key) + "=" + detail::format_real(w[0]));
    if (!scene.was_set(to_key)) scene.set(std::string(to_key) + "=" + detail::format_real(w[1]));
  }
  so.early_from_s = scene.get_real(from_key);
  so.early_to_s = scene.get_real(to_key);
  if (!(so.early_to_s > so.early_from_s))
    throw SceneError(std::string(to_key) + " = " + detail::format_real(so.early_to_s) +
                     " is not allowed: it must exceed " + from_key + " = " +
                     detail::format_real(so.early_from_s) +
                     " (the early fit's window, s after the contact's onset)");
}

void prepare_member(Member& m) {
  const SpreadOptions& so = m.so;
  if (!so.restart.empty()) {
    m.restart = read_checkpoint(so.restart);
    if (m.restart->text("app") != "spread")
      throw IoError(so.restart + ": a checkpoint of '" + m.restart->text("app") + "', not of spread");
    const double steps_done = m.restart->array("app.progress").at(0);  // Progress::step
    if (so.max_steps > 0 && static_cast<double>(so.max_steps) <= steps_done)
      throw SceneError("--max-steps " + std::to_string(so.max_steps) + " is not allowed with --restart " +
                       so.restart + ": the run has done " + detail::format_real(steps_done) +
                       " steps (--max-steps counts from the run's start); give a larger count");
  }
  m.scene = spread_scene(m.options, so, m.restart ? &*m.restart : nullptr);
  set_early_window(m);
  const Scene& scene = m.scene;
  if (!scene.get_bool("contact.plane"))
    throw SceneError(
        "contact.plane = false: spread needs the substrate plane (set contact.plane = true, or leave "
        "the key out)");
  const double h0 = scene.get_real("contact.h0_m"), gap = scene.get_real("contact.start_gap_m");
  const double cell_radius = scene.get_string("mesh.shape") == "sphere"
                                 ? scene.get_real("mesh.radius_m")
                                 : scene.get_real("mesh.diameter_m") / 2;
  const bool falls =
      scene.get_real("body.gravity_m_per_s2") > 0 && scene.get_real("body.density_excess_kg_per_m3") > 0;
  if (!(gap < h0) && !falls)
    throw SceneError("contact.start_gap_m = " + detail::format_real(gap) +
                     " is not allowed: it must be below contact.h0_m = " + detail::format_real(h0) +
                     " (the cell starts within the range of adhesion), unless gravity brings the cell down "
                     "(body.gravity_m_per_s2 > 0 with body.density_excess_kg_per_m3 > 0)");
  if (!(gap < h0)) {
    // The cell has to sink to the plane. Its weight is spread over the nodes, so the force vector's norm is
    // Δρ V g / √N: the CG's absolute tolerance must lie well below it, or the solve returns v = 0 and the
    // cell hangs in the fluid (the paper's 1e-14 N is larger than a 642-node RBC's weight norm, 4e-15 N).
    const double r = cell_radius;
    const double weight = scene.get_real("body.density_excess_kg_per_m3") * 4.0 / 3.0 * kPi * r * r * r *
                          scene.get_real("body.gravity_m_per_s2");
    const double norm = weight / std::sqrt(static_cast<double>(scene.get_int("mesh.nodes")));
    const auto g3 = [](double v) {
      char b[32];
      std::snprintf(b, sizeof b, "%.3g", v);
      return std::string(b);
    };
    if (scene.get_real("solver.cg_abs_tol_N") > 1e-3 * norm)
      throw SceneError("solver.cg_abs_tol_N = " + g3(scene.get_real("solver.cg_abs_tol_N")) +
                       " is too large for a cell that sinks to the plane (contact.start_gap_m >= "
                       "contact.h0_m): its weight per "
                       "node, " +
                       g3(norm) + " N in norm, needs a tolerance <= " + g3(1e-3 * norm) + " N");
  }
  // The rounded triangles' radius is capped at 1/geometry.h_min_per_m, meant for flattened regions; a cell
  // whose own radius reaches it gets spheres smaller than its triangles, in contact 100 um above the plane
  // (mesh.radius_m = 1e-3 reported r_cc = 482 um after one step, session 40).
  const double h_min = scene.get_real("geometry.h_min_per_m");
  if (!(cell_radius * h_min < 0.5))
    throw SceneError(
        (scene.get_string("mesh.shape") == "sphere"
             ? "mesh.radius_m = " + detail::format_real(cell_radius)
             : "mesh.diameter_m = " + detail::format_real(2 * cell_radius)) +
        " is too large for geometry.h_min_per_m = " + detail::format_real(h_min) +
        ": the rounded triangles' radius is capped at 1/h_min = " + detail::format_real(1 / h_min) +
        " m, which must be at least twice the cell's radius (set geometry.h_min_per_m <= " +
        detail::format_real(0.5 / cell_radius) + ")");
  // The paper's law must hold the cell: with a strong adhesion against a soft cortex (W = 1 J/m² with Table
  // 1's E) the Maugis–Dugdale load stays attractive up to an overlap of the cell's whole radius, and the cell
  // sank 1.2 um into the plane with exit 0 (session 40). Refused, with the largest W that holds it.
  if (scene.get_string("contact.law") == "maugis_dugdale") {
    const double E = scene.get_real("cortex.E_Pa"), nu = scene.get_real("cortex.nu");
    const auto load_at_full_overlap = [&](double W) {
      return md_state_from_radius(cell_radius, cell_radius, md_material(E, nu, W, h0)).P;
    };
    const double W = scene.get_real("contact.W_J_per_m2");
    if (!(load_at_full_overlap(W) > 0)) {
      double lo = 0, hi = W;  // the load at a = R is repulsive at lo, attractive at hi
      for (int k = 0; k < 100; ++k) {
        const double mid = 0.5 * (lo + hi);
        (load_at_full_overlap(mid) > 0 ? lo : hi) = mid;
      }
      char b[64];
      std::snprintf(b, sizeof b, "%.3g", lo);
      if (!(lo > 0))  // (with the ranges' extremes of E and h0 no adhesion holds the cell)
        throw SceneError("cortex.E_Pa = " + detail::format_real(E) +
                         " with contact.h0_m = " + detail::format_real(h0) +
                         ": the Maugis-Dugdale load stays attractive up to an overlap of the cell's radius "
                         "for any contact.W_J_per_m2 > 0; a stiffer cortex.E_Pa holds the cell");
      throw SceneError("contact.W_J_per_m2 = " + detail::format_real(W) +
                       " is too strong for this cell: with cortex.E_Pa = " + detail::format_real(E) +
                       " and contact.h0_m = " + detail::format_real(h0) +
                       " the Maugis-Dugdale load stays attractive up to an overlap of the cell's radius, so "
                       "nothing holds the cell on the plane; allowed: below " +
                       b + " J/m^2 (or a stiffer cortex.E_Pa)");
    }
  }
  m.dt = scene.get_real("time.dt_s");
  m.t_end = scene.get_real("time.t_end_s");
  m.steps = steps_from_scene(scene);
  m.cg = cg_settings_from_scene(scene);
  m.frame_every = scene.get_real("output.frame_every_s");
  m.per_decade = static_cast<double>(scene.get_int("output.series_per_decade"));
  m.checkpoint_every = scene.get_real("output.checkpoint_every_s");
  m.plane_z = scene.get_real("contact.plane_z_m");
  m.h0 = scene.get_real("contact.h0_m");
  m.mesh = cell_mesh_from_scene(scene);
  double zmin = INFINITY;
  for (const auto& x : m.mesh.nodes) zmin = std::min(zmin, x[2]);
  for (auto& x : m.mesh.nodes) x[2] += m.plane_z + gap - zmin;
  m.edge_mean = spread_fits::mean_edge_length(m.mesh.nodes, m.mesh.triangles);
  m.params = mechanics_from_scene(scene);
}

std::string batch_difference(const Member& a, const Member& b) {
  const auto g = [](double v) { return detail::format_real(v); };
  if (a.mesh.nodes.size() != b.mesh.nodes.size())
    return "mesh.nodes = " + std::to_string(b.mesh.nodes.size()) + " (the batch has " +
           std::to_string(a.mesh.nodes.size()) + "; a batch shares one mesh size)";
  const struct {
    const char* key;
    double x, y;
  } reals[] = {{"time.dt_s", a.steps.dt, b.steps.dt},
               {"time.adaptive", a.steps.adaptive ? 1.0 : 0.0, b.steps.adaptive ? 1.0 : 0.0},
               {"time.error_tol_m", a.steps.error_tol_m, b.steps.error_tol_m},
               {"time.dt_min_s", a.steps.dt_min, b.steps.dt_min},
               {"time.dt_max_s", a.steps.dt_max, b.steps.dt_max},
               {"time.contact_change", a.steps.contact_change, b.steps.contact_change},
               {"solver.cg_abs_tol_N", a.cg.abs_tol, b.cg.abs_tol},
               {"solver.cg_rel_tol", a.cg.rel_tol, b.cg.rel_tol},
               {"solver.cg_max_iterations", static_cast<double>(a.cg.max_iterations),
                static_cast<double>(b.cg.max_iterations)}};
  for (const auto& r : reals)
    if (r.x != r.y) return std::string(r.key) + " = " + g(r.y) + " (the batch has " + g(r.x) + ")";
  const std::string why = batch_mismatch(a.params, b.params);
  return why.empty() ? "" : "the scene: " + why;
}

std::vector<Member> read_batch(const std::string& path, const AppOptions& common, const SpreadOptions& so) {
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot read the batch file");
  std::vector<Member> ms;
  std::string line;
  int number = 0;
  std::vector<std::string> outs;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = path + ":" + std::to_string(number) + ": ";
    std::vector<std::string> words;
    try {
      words = split_words(line);
    } catch (const SceneError& e) {
      throw SceneError(where + e.what());
    }
    if (words.empty()) continue;
    Member& m = ms.emplace_back();
    m.options.quiet = common.quiet;
    m.options.threads = common.threads;
    m.so = so;
    for (std::size_t k = 0; k < words.size(); ++k) {
      const std::string& w = words[k];
      if ((w == "--set" || w == "--out") && k + 1 < words.size()) {
        (w == "--set" ? m.options.sets.push_back(words[k + 1]) : void(m.options.out_dir = words[k + 1]));
        ++k;
      } else if (w.rfind("--", 0) != 0 && k == 0) {
        if (!std::filesystem::exists(w)) throw SceneError(where + "scene file " + w + " does not exist");
        m.options.scene_path = w;
      } else {
        throw SceneError(where + "'" + w +
                         "' is not allowed: a member line is [SCENE.toml] [--set KEY=VALUE]... --out DIR");
      }
    }
    if (m.options.out_dir.empty()) throw SceneError(where + "a member needs --out DIR (its own folder)");
    for (const std::string& o : outs)
      if (o == m.options.out_dir)
        throw SceneError(where + "--out " + o + " is already another member's folder");
    outs.push_back(m.options.out_dir);
  }
  if (ms.empty()) throw SceneError(path + ": no member in the batch file");
  return ms;
}

}  // namespace spread_app
}  // namespace dcm
