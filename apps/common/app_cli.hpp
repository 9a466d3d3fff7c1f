#pragma once
// What every dcm app shares on the command line:
//   <app> [SCENE.toml] [--set key=value]... [--out DIR] [--threads N] [--quiet] [--list-keys] [--check]
// and one policy for failures: a one-line message on stderr and an exit code
//   2  bad input (command line, scene file, output folder), nothing written;
//   3  numerical trouble during a run (step, term and node named);
//   1  anything else (a bug: please report it).
#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/scene.hpp"

// CLI11 (CLI/CLI.hpp) costs about 10 s of compile time in every file that includes it; only the apps' main
// files and app_cli.cpp, which build command lines, include it.
namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace dcm {

// Thrown by an app that stopped on SIGINT/SIGTERM after closing its files; run_app returns 130.
struct AppInterrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// SIGINT/SIGTERM set a flag instead of killing the app (stretch, relax; spread has its own): the app checks
// stop_requested() between its steps, closes its files with what was done and throws AppInterrupted.
void install_stop_handler();
bool stop_requested();

struct AppOptions {
  std::string scene_path;         // empty: the built-in defaults
  std::vector<std::string> sets;  // key=value overrides, applied in order after the file
  std::string out_dir;            // empty: output.dir, else out/<name>
  int threads = 0;                // 0: OMP_NUM_THREADS or all cores
  bool quiet = false;
  bool check = false;  // --check: validate the scene and the options, then stop before writing anything
};

// Registers the shared options and the help's footer; `examples` are the app's own command lines
// (without the app's name), shown under "Examples:".
// interruptible: the app stops cleanly on Ctrl-C with exit code 130 (spread), which the footer then lists.
void add_common_options(CLI::App& app, AppOptions& options, const std::vector<std::string>& examples,
                        bool interruptible = false);

// A repeatable option that takes one value (or one comma-separated list, with ->delimiter(',')) per use,
// keeps every use, and leaves the next word to the positionals (a scene file after it stays the scene file);
// its help shows no "...", which read as a space-separated list. Returns `option`.
CLI::Option* one_value_per_use(CLI::Option* option);

// For --check: when it was given, checks the output folder (check_output_dir), prints "<app>: scene <name>:
// ok (checked, nothing written)" (unless --quiet) and returns true; the app then returns before creating its
// output folder.
bool stop_after_check(const std::string& app, const AppOptions& options, const Scene& scene);

// The scene from the file (or the built-in defaults changed by `without_file`, e.g. an app's own
// experiment), with every --set applied, validated. Throws SceneError. note_defaults: print a note (stdout)
// for each key of `without_file` that a given scene file leaves at the scene default.
Scene load_scene(const AppOptions& options, const std::vector<std::string>& without_file = {},
                 bool note_defaults = false);

// The output folder: --out, else output.dir, else out/<scene name>.
std::string output_dir_of(const AppOptions& options, const Scene& scene);

// For --check: throws IoError (the message a run would give) when a run could not create or write the
// folder `dir`; leaves nothing behind (a probe folder in it, or in its nearest existing parent, is made and
// removed).
void check_output_dir(const std::string& dir);

// output_dir_of(). Creates it; throws IoError if it cannot be written.
std::string prepare_output_dir(const AppOptions& options, const Scene& scene);

// A new run in a folder that held an earlier one: the files of that run (`names`, the app's outputs) go
// first, so that none of them (a summary, a checkpoint, plots of other data) is left beside a run that stops
// early. Throws IoError if one cannot be removed.
void remove_earlier_outputs(const std::string& dir, std::initializer_list<const char*> names);

// The running app's absolute path (/proc/self/exe), for the commands it suggests ("continue with: ...") to
// work from any folder; `name` where that cannot be read.
std::string program_path(const std::string& name);

// Parses the command line and runs body with the failure policy above. Returns the exit code.
int run_app(CLI::App& app, int argc, char** argv, const std::function<void()>& body);

}  // namespace dcm
