#pragma once
// A scene: every run-time setting of a dcm run, parsed from TOML and/or `--set key=value`.
//
// One schema (scene_schema()) lists every key with its type, default, unit, allowed range and a line of
// documentation. The parser, `--set`, `--help` and docs/SCENES.md all come from it, so a key cannot be
// known to one and unknown to another. Keys are dotted: "mesh.subdivisions" is `subdivisions` in the
// `[mesh]` table. Values are SI.
//
// Errors: every problem is a SceneError whose what() is ONE line naming the file, the key, the value
// and what is allowed, e.g.
//   scenes/x.toml: mesh.subdivisions = 9 is out of range: allowed 0 .. 6
//   scenes/x.toml: unknown key 'mesh.radus' (did you mean 'mesh.radius_m'?)
//   scenes/x.toml: mesh.radius_m = "big" has the wrong type: expected a real number (m)
#include <cstddef>
#include <initializer_list>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace dcm {

struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class ParamType { Int, Real, Bool, String };

struct ParamSpec {
  std::string key;  // dotted, e.g. "mesh.radius_m"
  ParamType type;
  std::string default_value;  // as TOML text: "4", "3.25e-6", "true", "sphere"
  double min = 0, max = 0;    // numeric range, used when has_range
  bool has_range = false;
  bool min_exclusive = false;        // (min, max] instead of [min, max]
  std::vector<std::string> choices;  // allowed strings (String) or values (Int), empty = any
  std::string unit;                  // "m", "N/m", "" for dimensionless
  std::string doc;                   // one line
};

const std::vector<ParamSpec>& scene_schema();

class Scene {
 public:
  // All defaults; name "default".
  static Scene defaults();
  // Parses a TOML file; unknown keys, wrong types and out-of-range values throw SceneError.
  // The scene name defaults to the file's stem.
  static Scene from_file(const std::string& path);
  static Scene from_string(const std::string& toml_text, const std::string& origin);

  // "key=value", value in TOML syntax or bare text for strings: mesh.subdivisions=3, mesh.shape=evans_fung
  void set(const std::string& key_equals_value);

  // Cross-key consistency (e.g. contact.h0_m below the cell radius); throws SceneError.
  // from_file()/from_string() call it; call it again after set().
  void validate() const;

  long long get_int(const std::string& key) const;
  double get_real(const std::string& key) const;
  bool get_bool(const std::string& key) const;
  const std::string& get_string(const std::string& key) const;
  bool was_set(const std::string& key) const;  // given in the file or by set(), not a default
  // Any key's value as its canonical text (TOML syntax for numbers and booleans, bare text for strings).
  const std::string& value_text(const std::string& key) const;

  const std::string& name() const { return name_; }
  const std::string& origin() const { return origin_; }  // file path or "defaults"
  // The resolved scene as TOML text (every key, defaults included), for provenance in outputs.
  std::string to_toml() const;

 private:
  std::string name_ = "default";
  std::string origin_ = "defaults";
  std::map<std::string, std::string> values_;  // key -> canonical value text
  std::map<std::string, bool> set_;
  bool nodes_by_set_ = false, subdivisions_by_set_ = false;  // mesh.nodes, mesh.subdivisions given by set()
  std::set<std::string> by_set_;                             // the keys set() gave (validate()'s label)

  // Stores a checked canonical value; "name" also updates name_ (empty: the name from origin_).
  void assign(const std::string& key, const std::string& canonical, bool given);
  // Keeps mesh.nodes and mesh.subdivisions consistent after `key` (one of them) was assigned.
  void follow_mesh_size(const std::string& key);
  // The label of a cross-key error about `keys`: "--set" when set() gave one of them, else origin_.
  const std::string& origin_of(std::initializer_list<const char*> keys) const;
};

// The schema as Markdown (a table per section) for docs/SCENES.md and --help-scene.
std::string scene_schema_markdown();

// The number of one-character insertions, deletions and substitutions that turn a into b (Levenshtein): what
// the "did you mean" hints for scene keys and command-line options measure.
std::size_t edit_distance(const std::string& a, const std::string& b);

namespace detail {
// Shortest of %.15g, %.16g, %.17g that reads back as v exactly; "nan", "inf", "-inf" for non-finite.
std::string format_real(double v);
// What a key allows, as error messages and the Markdown show it: "0 .. 6", "> 0 and ≤ 0.001",
// "sphere, evans_fung".
std::string allowed_text(const ParamSpec& spec);
}  // namespace detail

}  // namespace dcm
