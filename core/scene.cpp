// Scene: parsing (toml++), validation against scene_schema(), `--set`, accessors and TOML output.
#include "core/scene.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace dcm {
namespace {

using detail::format_real;

const char* const kNodes = "mesh.nodes";
const char* const kSubdivisions = "mesh.subdivisions";
const char* const kSetOrigin = "--set";

// ---- schema look-ups -----------------------------------------------------------------------------

const ParamSpec* find_spec(const std::string& key) {
  for (const ParamSpec& s : scene_schema()) {
    if (s.key == key) return &s;
  }
  return nullptr;
}

std::string section_of(const std::string& key) {
  const auto dot = key.find('.');
  return dot == std::string::npos ? std::string() : key.substr(0, dot);
}

std::string leaf_of(const std::string& key) {
  const auto dot = key.find('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

// Tables in schema order.
std::vector<std::string> schema_sections() {
  std::vector<std::string> out;
  for (const ParamSpec& s : scene_schema()) {
    const std::string sec = section_of(s.key);
    if (!sec.empty() && std::find(out.begin(), out.end(), sec) == out.end()) out.push_back(sec);
  }
  return out;
}

bool is_section(const std::string& name) {
  const std::vector<std::string> all = schema_sections();
  return std::find(all.begin(), all.end(), name) != all.end();
}

// Leaf names of the keys in one table ("" = top level), schema order.
std::vector<std::string> keys_in_section(const std::string& section) {
  std::vector<std::string> out;
  for (const ParamSpec& s : scene_schema()) {
    if (section_of(s.key) == section) out.push_back(leaf_of(s.key));
  }
  return out;
}

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
  return out;
}

// ---- text helpers --------------------------------------------------------------------------------

std::string trim(const std::string& s) {
  const char* ws = " \t\r\n";
  const auto first = s.find_first_not_of(ws);
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(ws) - first + 1);
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

// A TOML basic string: "..." with escapes.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (c < 0x20 || c == 0x7f) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

// ---- unknown keys --------------------------------------------------------------------------------

// The schema key closest to `key` if it is close enough (distance <= max(2, len/3)), else "".
// A key without a dot is also compared with the keys' leaf names ("radius_m" -> "mesh.radius_m").
std::string closest_key(const std::string& key) {
  const size_t limit = std::max<size_t>(2, key.size() / 3);
  std::string best;
  size_t best_distance = limit + 1;
  for (const ParamSpec& s : scene_schema()) {
    size_t d = edit_distance(key, s.key);
    if (key.find('.') == std::string::npos) d = std::min(d, edit_distance(key, leaf_of(s.key)));
    if (d < best_distance) {
      best_distance = d;
      best = s.key;
    }
  }
  return best;
}

std::string known_tables_text() { return "known tables: " + join(schema_sections(), ", "); }

std::string unknown_key_message(const std::string& key) {
  const std::string head = "unknown key '" + key + "'";
  const std::string best = closest_key(key);
  if (!best.empty()) return head + " (did you mean '" + best + "'?)";
  const std::string section = section_of(key);
  if (section.empty()) {
    return head + " (known top-level keys: " + join(keys_in_section(""), ", ") + "; " + known_tables_text() +
           ")";
  }
  if (is_section(section)) {
    return head + " (known keys in [" + section + "]: " + join(keys_in_section(section), ", ") + ")";
  }
  return head + " (" + known_tables_text() + ")";
}

std::string unknown_table_message(const std::string& table) {
  const std::string head = "unknown table [" + table + "]";
  for (const std::string& sec : schema_sections()) {
    if (edit_distance(table, sec) <= std::max<size_t>(2, table.size() / 3)) {
      return head + " (did you mean [" + sec + "]?)";
    }
  }
  return head + " (" + known_tables_text() + ")";
}

[[noreturn]] void fail(const std::string& origin, const std::string& message) {
  throw SceneError(origin + ": " + one_line(message));
}

// ---- values --------------------------------------------------------------------------------------

// A TOML node as it reads in a message: strings quoted, reals in shortest round-trip form.
std::string node_text(const toml::node& node) {
  if (const auto* s = node.as_string()) return quoted(s->get());
  if (const auto* i = node.as_integer()) return std::to_string(i->get());
  if (const auto* f = node.as_floating_point()) {  // a whole-number real keeps its ".0": 162.0 is not 162
    const std::string t = format_real(f->get());
    return t.find_first_of(".eEni") == std::string::npos ? t + ".0" : t;
  }
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  if (node.is_table()) return "{...}";
  std::ostringstream os;
  node.visit([&os](const auto& n) { os << n; });
  return one_line(os.str());
}

std::string expected_text(const ParamSpec& spec) {
  switch (spec.type) {
    case ParamType::Int:
      return "an integer";
    case ParamType::Real:
      return spec.unit.empty() ? "a real number" : "a real number (" + spec.unit + ")";
    case ParamType::Bool:
      return "true or false";
    case ParamType::String:
      return "a string";
  }
  return "?";
}

[[noreturn]] void fail_wrong_type(const std::string& origin, const ParamSpec& spec, const std::string& text) {
  fail(origin, spec.key + " = " + text + " has the wrong type: expected " + expected_text(spec));
}

[[noreturn]] void fail_out_of_range(const std::string& origin, const ParamSpec& spec,
                                    const std::string& text) {
  fail(origin, spec.key + " = " + text + " is out of range: allowed " + detail::allowed_text(spec));
}

[[noreturn]] void fail_not_a_choice(const std::string& origin, const ParamSpec& spec,
                                    const std::string& text) {
  fail(origin, spec.key + " = " + text + " is not allowed: choose one of " + join(spec.choices, ", "));
}

bool is_choice(const ParamSpec& spec, const std::string& canonical) {
  return spec.choices.empty() ||
         std::find(spec.choices.begin(), spec.choices.end(), canonical) != spec.choices.end();
}

bool in_range(const ParamSpec& spec, double v) {
  if (!std::isfinite(v)) return false;
  if (!spec.has_range) return true;
  const bool above_min = spec.min_exclusive ? v > spec.min : v >= spec.min;
  return above_min && v <= spec.max;
}

std::string checked_int(const ParamSpec& spec, long long v, const std::string& origin) {
  std::string text = std::to_string(v);
  if (!is_choice(spec, text)) fail_not_a_choice(origin, spec, text);
  if (!in_range(spec, static_cast<double>(v))) fail_out_of_range(origin, spec, text);
  return text;
}

std::string checked_real(const ParamSpec& spec, double v, const std::string& origin) {
  std::string text = format_real(v);
  if (!in_range(spec, v)) fail_out_of_range(origin, spec, text);
  return text;
}

std::string checked_string(const ParamSpec& spec, const std::string& v, const std::string& origin) {
  if (!is_choice(spec, v)) fail_not_a_choice(origin, spec, quoted(v));
  return v;
}

// Checks a TOML value against its key's spec; returns the canonical text.
std::string canonical_value(const ParamSpec& spec, const toml::node& node, const std::string& origin) {
  switch (spec.type) {
    case ParamType::Int:
      if (!node.is_integer()) fail_wrong_type(origin, spec, node_text(node));
      return checked_int(spec, node.as_integer()->get(), origin);
    case ParamType::Real:
      if (node.is_floating_point()) return checked_real(spec, node.as_floating_point()->get(), origin);
      if (node.is_integer()) return checked_real(spec, static_cast<double>(node.as_integer()->get()), origin);
      fail_wrong_type(origin, spec, node_text(node));
    case ParamType::Bool:
      if (!node.is_boolean()) fail_wrong_type(origin, spec, node_text(node));
      return node.as_boolean()->get() ? "true" : "false";
    case ParamType::String:
      if (!node.is_string()) fail_wrong_type(origin, spec, node_text(node));
      return checked_string(spec, node.as_string()->get(), origin);
  }
  throw std::logic_error("dcm::Scene: unhandled parameter type for " + spec.key);
}

// A `--set` value: TOML syntax, or bare text for a String key.
std::string canonical_from_text(const ParamSpec& spec, const std::string& raw, const std::string& origin) {
  try {
    const toml::table t = toml::parse("v = " + raw, origin);
    const toml::node* node = t.get("v");
    if (t.size() == 1 && node && (spec.type != ParamType::String || node->is_string())) {
      return canonical_value(spec, *node, origin);
    }
  } catch (const toml::parse_error&) {
    // not a TOML value: bare text
  }
  if (spec.type == ParamType::String) return checked_string(spec, raw, origin);
  fail_wrong_type(origin, spec, raw);
}

std::string canonical_default(const ParamSpec& spec) {
  if (spec.type == ParamType::Real) return format_real(std::strtod(spec.default_value.c_str(), nullptr));
  return spec.default_value;
}

// ---- mesh size -----------------------------------------------------------------------------------

long long nodes_for_subdivisions(long long k) { return 10 * (1LL << (2 * k)) + 2; }

long long subdivisions_for_nodes(long long nodes) {
  for (long long k = 0; k <= 15; ++k) {
    if (nodes_for_subdivisions(k) == nodes) return k;
  }
  throw std::logic_error("dcm::Scene: mesh.nodes = " + std::to_string(nodes) + " is not 10*4^k+2");
}

// ---- TOML documents ------------------------------------------------------------------------------

toml::table parse_document(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    const auto& begin = e.source().begin;
    throw SceneError(origin + ":" + std::to_string(begin.line) + ":" + std::to_string(begin.column) +
                     ": TOML syntax error: " + one_line(std::string(e.description())));
  }
}

using Entry = std::pair<std::string, const toml::node*>;

// A table's entries in the order they appear in the file (toml++ keeps them sorted by name).
std::vector<Entry> entries_in_file_order(const toml::table& table) {
  std::vector<std::pair<toml::source_position, Entry>> items;
  for (const auto& [key, node] : table) {
    items.push_back({key.source().begin, Entry(std::string(key.str()), &node)});
  }
  std::stable_sort(items.begin(), items.end(), [](const auto& a, const auto& b) {
    return a.first.line != b.first.line ? a.first.line < b.first.line : a.first.column < b.first.column;
  });
  std::vector<Entry> out;
  for (auto& item : items) out.push_back(std::move(item.second));
  return out;
}

// Throws for an entry at top level that is neither a key nor a known table.
[[noreturn]] void fail_unknown_top_level(const std::string& name, const toml::node& node,
                                         const std::string& origin) {
  const toml::table* table = node.as_table();
  if (!table) fail(origin, unknown_key_message(name));
  const std::vector<Entry> entries = entries_in_file_order(*table);
  if (entries.empty()) fail(origin, unknown_table_message(name));
  fail(origin, unknown_key_message(name + "." + entries.front().first));
}

// The (dotted key, value) pairs of a scene document in file order; throws for anything that is not a key
// of the schema: unknown keys and tables, nested tables, arrays of tables.
std::vector<Entry> flatten_document(const toml::table& root, const std::string& origin) {
  std::vector<Entry> out;
  for (const auto& [top_key, node] : entries_in_file_order(root)) {
    if (find_spec(top_key)) {
      out.emplace_back(top_key, node);
      continue;
    }
    if (!is_section(top_key)) fail_unknown_top_level(top_key, *node, origin);
    const toml::table* table = node->as_table();
    if (!table) {
      fail(origin,
           top_key + " = " + node_text(*node) + " has the wrong type: expected a table [" + top_key + "]");
    }
    for (const auto& [leaf, value] : entries_in_file_order(*table)) {
      const std::string key = top_key + "." + leaf;
      if (!find_spec(key)) fail(origin, unknown_key_message(key));
      out.emplace_back(key, value);
    }
  }
  return out;
}

void check_mesh_size_pair(long long nodes, long long subdivisions, const std::string& origin) {
  const long long implied = nodes_for_subdivisions(subdivisions);
  if (implied == nodes) return;
  fail(origin, std::string(kNodes) + " = " + std::to_string(nodes) + " and " + kSubdivisions + " = " +
                   std::to_string(subdivisions) + " disagree: " + std::to_string(subdivisions) +
                   " subdivisions give " + std::to_string(implied) + " nodes; give only one of them");
}

std::string fallback_name(const std::string& origin) {
  if (origin == "defaults" || origin == kSetOrigin) return "default";
  const std::filesystem::path path(origin);
  if (!path.has_extension() || path.stem().empty()) return "default";
  return path.stem().string();
}

const ParamSpec& spec_for(const std::string& key, ParamType type, const char* accessor) {
  const ParamSpec* spec = find_spec(key);
  if (!spec) throw std::logic_error(std::string("dcm::Scene::") + accessor + ": unknown key '" + key + "'");
  if (spec->type != type) {
    throw std::logic_error(std::string("dcm::Scene::") + accessor + ": key '" + key + "' has another type");
  }
  return *spec;
}

std::string toml_comment(const ParamSpec& spec) {
  return spec.unit.empty() ? spec.doc : spec.unit + " — " + spec.doc;
}

std::string toml_value(const ParamSpec& spec, const std::string& canonical) {
  return spec.type == ParamType::String ? quoted(canonical) : canonical;
}

}  // namespace

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// ---- Scene ---------------------------------------------------------------------------------------

Scene Scene::defaults() {
  Scene s;
  for (const ParamSpec& spec : scene_schema()) s.assign(spec.key, canonical_default(spec), false);
  return s;
}

Scene Scene::from_file(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  std::string text;
  int error = file ? 0 : errno;
  if (file) {
    char buf[1 << 14];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, file)) > 0) text.append(buf, n);
    if (std::ferror(file)) error = errno ? errno : EIO;
    std::fclose(file);
  }
  if (error) throw SceneError(path + ": cannot read scene file (" + std::strerror(error) + ")");
  Scene s = from_string(text, path);
  if (!s.was_set("name")) s.assign("name", std::filesystem::path(path).stem().string(), false);
  return s;
}

Scene Scene::from_string(const std::string& toml_text, const std::string& origin) {
  const toml::table root = parse_document(toml_text, origin);
  Scene s = defaults();
  s.origin_ = origin;
  s.assign("name", "", false);
  for (const auto& [key, node] : flatten_document(root, origin)) {
    s.assign(key, canonical_value(*find_spec(key), *node, origin), true);
  }
  if (s.was_set(kNodes) && s.was_set(kSubdivisions)) {
    check_mesh_size_pair(s.get_int(kNodes), s.get_int(kSubdivisions), origin);
  } else if (s.was_set(kNodes)) {
    s.follow_mesh_size(kNodes);
  } else if (s.was_set(kSubdivisions)) {
    s.follow_mesh_size(kSubdivisions);
  }
  s.validate();
  return s;
}

void Scene::set(const std::string& key_equals_value) {
  const auto eq = key_equals_value.find('=');
  if (eq == std::string::npos) fail(kSetOrigin, "expected key=value, got '" + key_equals_value + "'");
  const std::string key = trim(key_equals_value.substr(0, eq));
  const ParamSpec* spec = find_spec(key);
  if (!spec) fail(kSetOrigin, unknown_key_message(key));
  const std::string canonical = canonical_from_text(*spec, trim(key_equals_value.substr(eq + 1)), kSetOrigin);
  if (key == kNodes || key == kSubdivisions) {
    // Two --set of the mesh size must agree, as the two keys in one file must; a --set of one of them
    // overrides what a file gave (the other follows it).
    const bool nodes_now = key == kNodes;
    if (nodes_now ? subdivisions_by_set_ : nodes_by_set_) {
      const long long value = std::strtoll(canonical.c_str(), nullptr, 10);
      check_mesh_size_pair(nodes_now ? value : get_int(kNodes), nodes_now ? get_int(kSubdivisions) : value,
                           kSetOrigin);
    }
    (nodes_now ? nodes_by_set_ : subdivisions_by_set_) = true;
  }
  assign(key, canonical, true);
  by_set_.insert(key);
  if (key == kNodes || key == kSubdivisions) follow_mesh_size(key);
}

const std::string& Scene::origin_of(std::initializer_list<const char*> keys) const {
  static const std::string set_origin = kSetOrigin;
  for (const char* k : keys)
    if (by_set_.count(k) != 0) return set_origin;
  return origin_;
}

void Scene::validate() const {
  // The name is a folder under out/: a path in it wrote outside out/ (name = "../../escape", session 41).
  if (name_.find('/') != std::string::npos || name_.find('\\') != std::string::npos || name_ == "." ||
      name_ == "..")
    fail(origin_of({"name"}),
         "name = '" + name_ +
             "' is not allowed: a folder name under out/ (no '/' or '\\', not '.' or '..'); to write "
             "elsewhere set output.dir or --out");
  if (get_int("mesh.refine_levels") > 0 &&
      !(get_real("mesh.refine_from_deg") < get_real("mesh.refine_to_deg")))
    fail(origin_of({"mesh.refine_from_deg", "mesh.refine_to_deg", "mesh.refine_levels"}),
         "mesh.refine_to_deg = " + format_real(get_real("mesh.refine_to_deg")) +
             " is not allowed: the refined band must end above mesh.refine_from_deg = " +
             format_real(get_real("mesh.refine_from_deg")));
  const double h0 = get_real("contact.h0_m");
  const bool sphere = get_string("mesh.shape") == "sphere";
  const double radius = sphere ? get_real("mesh.radius_m") : get_real("mesh.diameter_m") / 2;
  if (!(h0 < radius)) {
    fail(origin_of({"contact.h0_m", "mesh.shape", "mesh.radius_m", "mesh.diameter_m"}),
         "contact.h0_m = " + format_real(h0) + " must be smaller than the cell radius " +
             (sphere ? "mesh.radius_m" : "mesh.diameter_m/2") + " = " + format_real(radius));
  }
}

long long Scene::get_int(const std::string& key) const {
  spec_for(key, ParamType::Int, "get_int");
  return std::strtoll(values_.at(key).c_str(), nullptr, 10);
}

double Scene::get_real(const std::string& key) const {
  spec_for(key, ParamType::Real, "get_real");
  return std::strtod(values_.at(key).c_str(), nullptr);
}

bool Scene::get_bool(const std::string& key) const {
  spec_for(key, ParamType::Bool, "get_bool");
  return values_.at(key) == "true";
}

const std::string& Scene::get_string(const std::string& key) const {
  spec_for(key, ParamType::String, "get_string");
  return values_.at(key);
}

const std::string& Scene::value_text(const std::string& key) const {
  const auto it = values_.find(key);
  if (it == values_.end()) throw std::logic_error("Scene::value_text: no key " + key);
  return it->second;
}

bool Scene::was_set(const std::string& key) const {
  if (!find_spec(key)) throw std::logic_error("dcm::Scene::was_set: unknown key '" + key + "'");
  const auto it = set_.find(key);
  return it != set_.end() && it->second;
}

std::string Scene::to_toml() const {
  std::ostringstream os;
  os << "# dcm scene, resolved (every key, defaults included); origin: " << one_line(origin_) << "\n";
  for (const ParamSpec& spec : scene_schema()) {  // top-level keys must precede the first table
    if (section_of(spec.key).empty()) {
      os << spec.key << " = " << toml_value(spec, values_.at(spec.key)) << "  # " << toml_comment(spec)
         << "\n";
    }
  }
  for (const std::string& section : schema_sections()) {
    os << "\n[" << section << "]\n";
    for (const ParamSpec& spec : scene_schema()) {
      if (section_of(spec.key) != section) continue;
      os << leaf_of(spec.key) << " = " << toml_value(spec, values_.at(spec.key)) << "  # "
         << toml_comment(spec) << "\n";
    }
  }
  return os.str();
}

void Scene::assign(const std::string& key, const std::string& canonical, bool given) {
  values_[key] = canonical;
  set_[key] = given;
  if (key == "name") {
    name_ = canonical.empty() ? fallback_name(origin_) : canonical;
    values_[key] = name_;
  }
}

void Scene::follow_mesh_size(const std::string& key) {
  if (key == kNodes) {
    values_[kSubdivisions] = std::to_string(subdivisions_for_nodes(get_int(kNodes)));
    set_[kSubdivisions] = false;
  } else {
    values_[kNodes] = std::to_string(nodes_for_subdivisions(get_int(kSubdivisions)));
    set_[kNodes] = false;
  }
}

}  // namespace dcm
