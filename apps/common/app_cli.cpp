#include "apps/common/app_cli.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "core/h5_output.hpp"

namespace dcm {

CLI::Option* one_value_per_use(CLI::Option* option) {
  return option->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)->allow_extra_args(false);
}

void add_common_options(CLI::App& app, AppOptions& o, const std::vector<std::string>& examples,
                        bool interruptible) {
  std::string footer = "Examples:\n";
  for (const std::string& e : examples) footer += "  " + app.get_name() + (e.empty() ? "" : " ") + e + "\n";
  app.footer(footer + "Exit codes: 0 success, 2 bad input (nothing written), 3 numerical failure, " +
             std::string(interruptible ? "130 interrupted (Ctrl-C; what was done is kept), " : "") +
             "1 internal error.\n"
             "Scene keys: --list-keys or docs/SCENES.md.");
  // No CLI::ExistingFile check: it ran before the unknown options were reported, so `geometry --nodes 642`
  // said "File does not exist: 642"; Scene::from_file names a missing file itself.
  app.add_option("scene", o.scene_path, "Scene file (TOML); without one the built-in defaults run");
  app.add_option("--set", o.sets,
                 "Override a scene key; one KEY=VALUE per --set, repeat it for more: --set mesh.nodes=642 "
                 "--set mesh.shape=evans_fung (--list-keys shows every key)")
      ->type_name("KEY=VALUE");
  one_value_per_use(app.get_option("--set"));
  app.add_option("--out", o.out_dir,
                 "Output folder (default: the scene's output.dir, else out/<scene name>)");
  app.add_option("--threads", o.threads, "Host threads (0 or not given: OMP_NUM_THREADS, else all cores)")
      ->check(CLI::Range(0, 4096));
  app.add_flag("--quiet", o.quiet, "Print only errors");
  app.add_flag("--check", o.check,
               "Only check the scene and the options (exit 0, or 2 with the error); write and run nothing");
  app.add_flag_callback(
      "--list-keys",
      [] {
        std::cout << scene_schema_markdown();
        throw CLI::Success();
      },
      "Print every scene key with its type, default, unit and allowed range, then exit");
}

namespace {

// A KEY=VALUE that did not follow a --set of its own.
std::string own_set_hint(const std::string& word) {
  return "each scene key needs its own --set (--set " + word + ")";
}

// True when `word` is one number or a comma-separated list of numbers ("50", "0,50", "-.5").
bool is_number_list(const std::string& word) {
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = word.find(',', start);
    const std::string item =
        word.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0') return false;
    if (comma == std::string::npos) return true;
    start = comma + 1;
  }
}

// A KEY=VALUE or a number where the scene file goes is a value that an option did not take: one key per
// --set, and an option with several values takes them comma-separated (`stretch --forces-pN 0 50` read 50 as
// the scene file).
void check_scene_path(const std::string& path) {
  std::error_code ec;  // a name too long for the file system is Scene::from_file's to refuse (exit 2)
  if (path.empty() || std::filesystem::exists(path, ec)) return;
  // `--set a=1 b=2` without a scene file: b=2 lands here (its value may be a path: output.dir=/tmp/x).
  const std::size_t eq = path.find('=');
  if (eq != std::string::npos && eq > 0 && path.substr(0, eq).find('/') == std::string::npos)
    throw SceneError("'" + path + "' was read as the scene file: " + own_set_hint(path));
  if (is_number_list(path))
    throw SceneError("'" + path +
                     "' was read as the scene file: a value goes right after its option, and a " +
                     "list is one word, comma-separated without spaces (e.g. stretch --forces-pN 0,50)");
}

}  // namespace

Scene load_scene(const AppOptions& o, const std::vector<std::string>& without_file, bool note_defaults) {
  check_scene_path(o.scene_path);
  Scene scene = o.scene_path.empty() ? Scene::defaults() : Scene::from_file(o.scene_path);
  if (o.scene_path.empty())
    for (const std::string& s : without_file) scene.set(s);
  for (const std::string& s : o.sets) scene.set(s);
  scene.validate();
  // note_defaults (stretch, relax): a scene file that leaves out a key the app sets without one (mesh.shape =
  // evans_fung) runs the scene default instead: say so, since --list-keys shows the default, not what the app
  // runs without a file (session 41: a scene with only cortex keys stretched a sphere without a word).
  if (note_defaults && !o.scene_path.empty() && !o.quiet)
    for (const std::string& s : without_file) {
      const std::string key = s.substr(0, s.find('='));
      if (key != "name" && !scene.was_set(key))
        std::printf("note: %s sets no %s: the scene default %s is used (without a scene file: %s)\n",
                    o.scene_path.c_str(), key.c_str(), scene.value_text(key).c_str(),
                    s.substr(s.find('=') + 1).c_str());
    }
  return scene;
}

bool stop_after_check(const std::string& app, const AppOptions& o, const Scene& scene) {
  if (!o.check) return false;
  check_output_dir(output_dir_of(o, scene));
  if (!o.quiet)
    std::printf("%s: scene %s: ok (checked, nothing written)\n", app.c_str(), scene.name().c_str());
  return true;
}

namespace {
volatile std::sig_atomic_t g_stop_requested = 0;
// The first signal asks for a clean stop; the handler then steps aside, so that a second Ctrl-C ends the app
// at once (a Newton solve of a fine mesh can take minutes before the next check).
extern "C" void on_stop_signal(int sig) {
  g_stop_requested = 1;
  std::signal(sig, SIG_DFL);
}
}  // namespace

void install_stop_handler() {
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
}

bool stop_requested() { return g_stop_requested != 0; }

std::string output_dir_of(const AppOptions& o, const Scene& scene) {
  std::string dir = o.out_dir;
  if (dir.empty()) dir = scene.get_string("output.dir");
  if (dir.empty()) dir = "out/" + scene.name();
  return dir;
}

void check_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path existing = fs::absolute(dir, ec).lexically_normal();
  if (ec) throw IoError(dir + ": cannot create the output folder (" + ec.message() + ")");
  // The folder, else the nearest of its parents that exists: the one a run writes in or creates folders in.
  while (!fs::exists(existing, ec) && existing.has_parent_path() && existing.parent_path() != existing)
    existing = existing.parent_path();
  if (!fs::is_directory(existing, ec))
    throw IoError(dir + ": cannot create the output folder (" + existing.string() + " is not a folder)");
  // A probe folder, made and removed at once: what the run's first step there (create a folder or a file)
  // needs, whoever runs it and whatever the file system (access() says yes to root on /proc).
  std::string probe = (existing / ".dcm-check-XXXXXX").string();
  if (!mkdtemp(probe.data()))
    throw IoError(dir + ": cannot create the output folder (" + existing.string() + ": " +
                  std::strerror(errno) + ")");
  fs::remove(probe, ec);
}

std::string prepare_output_dir(const AppOptions& o, const Scene& scene) {
  namespace fs = std::filesystem;
  std::string dir = output_dir_of(o, scene);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(dir + ": cannot create the output folder (" + ec.message() + ")");
  const fs::path probe = fs::path(dir) / ".dcm-write-test";
  FILE* f = std::fopen(probe.c_str(), "w");
  if (!f) throw IoError(dir + ": the output folder is not writable");
  std::fclose(f);
  fs::remove(probe, ec);
  return dir;
}

void remove_earlier_outputs(const std::string& dir, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    std::error_code ec;
    std::filesystem::remove(std::filesystem::path(dir) / name, ec);
    if (ec) throw IoError(dir + "/" + name + ": cannot remove the earlier run's file (" + ec.message() + ")");
  }
}

std::string program_path(const std::string& name) {
  std::error_code ec;
  std::string self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
  // A binary rebuilt while it runs reads "<path> (deleted)": the new one is at <path>.
  const std::string deleted = " (deleted)";
  if (self.size() > deleted.size() &&
      self.compare(self.size() - deleted.size(), deleted.size(), deleted) == 0)
    self.resize(self.size() - deleted.size());
  return ec || self.empty() ? name : self;
}

namespace {

// An option, not a value: "--x", "-x"; not "-5", "-.5" or "-".
bool looks_like_option(const std::string& word) {
  return word.size() > 1 && word[0] == '-' && !std::isdigit(static_cast<unsigned char>(word[1])) &&
         word[1] != '.';
}

// For CLI::ExtrasError: the first unknown option with the nearest known one, else the first stray value, with
// a hint that fits the app (one with --set, one with a scene file).
std::string unexpected_arguments_message(const CLI::App& app, const std::vector<std::string>& extras) {
  // An option first (`--ouy x` leaves "--ouy" and "x"): the value after it is the option's.
  std::string word = extras.empty() ? std::string() : extras.front();
  for (const std::string& e : extras)
    if (looks_like_option(e)) {
      word = e;
      break;
    }
  if (looks_like_option(word)) {
    const std::string flag = word.substr(0, word.find('='));
    // Long options only: every two-letter word is one edit from -h.
    std::string best;
    if (flag.size() > 2 && flag[1] == '-') {
      std::size_t best_distance = std::max<std::size_t>(2, flag.size() / 3) + 1;
      for (const CLI::Option* opt : app.get_options())
        for (const std::string& n : opt->get_lnames()) {
          const std::size_t d = edit_distance(flag, "--" + n);
          if (d < best_distance) {
            best_distance = d;
            best = "--" + n;
          }
        }
    }
    return "unknown option '" + flag + "'" + (best.empty() ? "" : " (did you mean '" + best + "'?)");
  }
  const bool has_set = app.get_option_no_throw("--set") != nullptr;
  const bool has_scene = app.get_option_no_throw("scene") != nullptr;
  if (has_set && word.find('=') != std::string::npos)
    return "unexpected argument '" + word + "': " + own_set_hint(word);
  if (has_scene)
    return "unexpected argument '" + word +
           "': one scene file at most, and an option with several values takes them comma-separated";
  return "unexpected argument '" + word +
         "': this app takes options only, and an option with several values takes them comma-separated";
}

}  // namespace

int run_app(CLI::App& app, int argc, char** argv, const std::function<void()>& body) {
  const std::string name = app.get_name();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ExtrasError& e) {
    // CLI11 says "The following arguments were not expected: x --ouy": name the mistyped option instead.
    std::cerr << name << ": error: " << unexpected_arguments_message(app, app.remaining())
              << " (see --help)\n";
    return 2;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help (prints it), --list-keys (printed already)
    std::cerr << name << ": error: " << e.what() << " (see --help)\n";
    return 2;
  }
  try {
    body();
    return 0;
  } catch (const SceneError& e) {
    std::cerr << name << ": error: " << e.what() << '\n';
    return 2;
  } catch (const IoError& e) {
    std::cerr << name << ": error: " << e.what() << '\n';
    return 2;
  } catch (const NumericalError& e) {
    std::cerr << name << ": numerical failure: " << e.what() << '\n';
    return 3;
  } catch (const AppInterrupted& e) {
    std::cerr << name << ": " << e.what() << '\n';
    return 130;
  } catch (const std::exception& e) {
    std::cerr << name << ": internal error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace dcm
