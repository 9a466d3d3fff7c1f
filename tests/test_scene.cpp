// Tests of the scene module: schema defaults, parsing, error messages, --set, pairing, round trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "core/scene.hpp"
#include "dcm_config.hpp"

#ifndef DCM_SOURCE_DIR
#error "DCM_SOURCE_DIR must be defined to the repository root"
#endif

namespace dcm {
namespace {

std::string source_path(const std::string& relative) { return std::string(DCM_SOURCE_DIR) + "/" + relative; }

// The SceneError message of f(), or "" when f() does not throw one.
template <class F>
std::string scene_error(F f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

std::string file_error(const std::string& relative) {
  return scene_error([&] { Scene::from_file(source_path(relative)); });
}

std::string string_error(const std::string& text) {
  return scene_error([&] { Scene::from_string(text, "t.toml"); });
}

std::string set_error(const std::string& key_equals_value) {
  return scene_error([&] {
    Scene s = Scene::defaults();
    s.set(key_equals_value);
  });
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

void expect_one_line(const std::string& message) {
  EXPECT_FALSE(message.empty());
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

void expect_same_values(const Scene& a, const Scene& b, const std::vector<std::string>& except = {}) {
  EXPECT_EQ(a.name(), b.name());
  for (const ParamSpec& spec : scene_schema()) {
    if (std::find(except.begin(), except.end(), spec.key) != except.end()) continue;
    switch (spec.type) {
      case ParamType::Int:
        EXPECT_EQ(a.get_int(spec.key), b.get_int(spec.key)) << spec.key;
        break;
      case ParamType::Real:
        EXPECT_EQ(a.get_real(spec.key), b.get_real(spec.key)) << spec.key;
        break;
      case ParamType::Bool:
        EXPECT_EQ(a.get_bool(spec.key), b.get_bool(spec.key)) << spec.key;
        break;
      case ParamType::String:
        EXPECT_EQ(a.get_string(spec.key), b.get_string(spec.key)) << spec.key;
        break;
    }
  }
}

// ---- schema and defaults -------------------------------------------------------------------------

TEST(SceneSchema, KeysAreUniqueAndDefaultsLieInTheirRange) {
  const auto& schema = scene_schema();
  ASSERT_EQ(schema.size(), 67u);
  for (size_t i = 0; i < schema.size(); ++i) {
    for (size_t j = i + 1; j < schema.size(); ++j) EXPECT_NE(schema[i].key, schema[j].key);
    EXPECT_FALSE(schema[i].doc.empty()) << schema[i].key;
  }
  // Every default passes its own validation: a scene that sets every key to its default parses.
  std::string text;
  for (const ParamSpec& spec : schema) {
    if (spec.key == "name") continue;
    const std::string value =
        spec.type == ParamType::String ? "\"" + spec.default_value + "\"" : spec.default_value;
    text += spec.key + " = " + value + "\n";
  }
  EXPECT_NO_THROW(Scene::from_string(text, "all.toml"));
}

TEST(SceneDefaults, EqualTheSchema) {
  const Scene s = Scene::defaults();
  EXPECT_EQ(s.name(), "default");
  EXPECT_EQ(s.origin(), "defaults");
  for (const ParamSpec& spec : scene_schema()) {
    EXPECT_FALSE(s.was_set(spec.key)) << spec.key;
    switch (spec.type) {
      case ParamType::Int:
        EXPECT_EQ(s.get_int(spec.key), std::stoll(spec.default_value)) << spec.key;
        break;
      case ParamType::Real:
        EXPECT_EQ(s.get_real(spec.key), std::strtod(spec.default_value.c_str(), nullptr)) << spec.key;
        break;
      case ParamType::Bool:
        EXPECT_EQ(s.get_bool(spec.key), spec.default_value == "true") << spec.key;
        break;
      case ParamType::String:
        if (spec.key != "name") {
          EXPECT_EQ(s.get_string(spec.key), spec.default_value) << spec.key;
        }
        break;
    }
  }
  EXPECT_EQ(s.get_string("name"), "default");
  EXPECT_EQ(s.get_int("mesh.nodes"), 2562);
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 4);
  EXPECT_DOUBLE_EQ(s.get_real("mesh.radius_m"), 3.25e-6);
  EXPECT_DOUBLE_EQ(s.get_real("cortex.E_Pa"), 800e3);
  EXPECT_DOUBLE_EQ(s.get_real("cortex.k_b_J"), 240e-21);
  EXPECT_EQ(s.get_string("mesh.shape"), "sphere");
  EXPECT_TRUE(s.get_bool("output.hdf5"));
  EXPECT_NO_THROW(s.validate());
}

TEST(SceneDefaults, AccessorMisuseIsALogicError) {
  const Scene s = Scene::defaults();
  EXPECT_THROW(s.get_int("mesh.radius_m"), std::logic_error);
  EXPECT_THROW(s.get_real("mesh.subdivisions"), std::logic_error);
  EXPECT_THROW(s.get_bool("mesh.shape"), std::logic_error);
  EXPECT_THROW(s.get_string("output.hdf5"), std::logic_error);
  EXPECT_THROW(s.get_real("mesh.radius"), std::logic_error);
  EXPECT_THROW(s.was_set("nope"), std::logic_error);
  // Not a SceneError: a programming error, not a user's.
  try {
    s.get_real("nope");
    FAIL() << "no exception";
  } catch (const SceneError&) {
    FAIL() << "SceneError for a programming error";
  } catch (const std::logic_error&) {
  }
}

// ---- shipped scene files -------------------------------------------------------------------------

// scenes/default.toml (the main job) lists every key; its values are the defaults except the four that
// make it a short spreading run.
TEST(SceneFiles, DefaultTomlListsEveryKeyAtItsDefaultButTheMainJobsFour) {
  const Scene s = Scene::from_file(source_path("scenes/default.toml"));
  EXPECT_EQ(s.name(), "default");
  EXPECT_EQ(s.origin(), source_path("scenes/default.toml"));
  Scene d = Scene::defaults();
  expect_same_values(s, d, {"name", "mesh.subdivisions", "mesh.nodes", "contact.plane", "time.t_end_s"});
  EXPECT_EQ(s.get_int("mesh.nodes"), 642);
  EXPECT_TRUE(s.get_bool("contact.plane"));
  EXPECT_DOUBLE_EQ(s.get_real("time.t_end_s"), 0.2);
  for (const ParamSpec& spec : scene_schema())
    if (spec.key != "mesh.nodes") {
      EXPECT_TRUE(s.was_set(spec.key)) << spec.key << " is not listed in scenes/default.toml";
    }
  EXPECT_FALSE(s.was_set("mesh.nodes"));  // commented out in the file
}

TEST(SceneFiles, EvansFung) {
  const Scene s = Scene::from_file(source_path("scenes/evans_fung.toml"));
  EXPECT_EQ(s.name(), "evans_fung");
  EXPECT_EQ(s.get_string("mesh.shape"), "evans_fung");
  EXPECT_EQ(s.get_int("mesh.nodes"), 2562);
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 4);
  EXPECT_DOUBLE_EQ(s.get_real("mesh.diameter_m"), 7.82e-6);
}

TEST(SceneFiles, MissingFile) {
  const std::string path = source_path("tests/scenes/does_not_exist.toml");
  const std::string msg = file_error("tests/scenes/does_not_exist.toml");
  expect_one_line(msg);
  EXPECT_EQ(msg, path + ": cannot read scene file (No such file or directory)");
}

TEST(SceneFiles, BadUnknownKey) {
  const std::string msg = file_error("tests/scenes/bad_unknown_key.toml");
  expect_one_line(msg);
  EXPECT_TRUE(
      contains(msg, "bad_unknown_key.toml: unknown key 'mesh.radus_m' (did you mean 'mesh.radius_m'?)"))
      << msg;
}

TEST(SceneFiles, BadNegativeRadius) {
  const std::string msg = file_error("tests/scenes/bad_negative_radius.toml");
  expect_one_line(msg);
  EXPECT_TRUE(contains(
      msg, "bad_negative_radius.toml: mesh.radius_m = -1e-06 is out of range: allowed > 0 and ≤ 0.001"))
      << msg;
}

TEST(SceneFiles, BadSubdivisions) {
  const std::string msg = file_error("tests/scenes/bad_subdivisions.toml");
  expect_one_line(msg);
  EXPECT_TRUE(contains(msg, "bad_subdivisions.toml: mesh.subdivisions = 9 is out of range: allowed 0 .. 6"))
      << msg;
}

TEST(SceneFiles, BadType) {
  const std::string msg = file_error("tests/scenes/bad_type.toml");
  expect_one_line(msg);
  EXPECT_TRUE(
      contains(msg, "bad_type.toml: mesh.subdivisions = \"four\" has the wrong type: expected an integer"))
      << msg;
}

TEST(SceneFiles, BadSyntaxNamesFileLineAndColumn) {
  const std::string msg = file_error("tests/scenes/bad_syntax.toml");
  expect_one_line(msg);
  EXPECT_TRUE(contains(msg, source_path("tests/scenes/bad_syntax.toml") + ":4:")) << msg;
  EXPECT_TRUE(contains(msg, ": TOML syntax error: ")) << msg;
}

TEST(SceneParse, MultiLineSyntaxErrorStaysOneLine) {
  const std::string msg = string_error("[mesh]\nshape = \"sphere\nradius_m = 1\n");
  expect_one_line(msg);
  EXPECT_EQ(msg.rfind("t.toml:2:", 0), 0u) << msg;
}

// ---- parsing -------------------------------------------------------------------------------------

TEST(SceneParse, NameFromKeyOrOrigin) {
  EXPECT_EQ(Scene::from_string("", "dir/run7.toml").name(), "run7");
  EXPECT_EQ(Scene::from_string("", "inline").name(), "default");
  const Scene named = Scene::from_string("name = \"cell\"\n", "dir/run7.toml");
  EXPECT_EQ(named.name(), "cell");
  EXPECT_EQ(named.get_string("name"), "cell");
  EXPECT_TRUE(named.was_set("name"));
}

TEST(SceneParse, ValuesAndWasSet) {
  const Scene s = Scene::from_string(
      "[cortex]\nnu = 0.3\n[output]\nhdf5 = false\ndir = \"/tmp/x\"\n[mesh]\nshape = \"evans_fung\"\n",
      "t.toml");
  EXPECT_DOUBLE_EQ(s.get_real("cortex.nu"), 0.3);
  EXPECT_FALSE(s.get_bool("output.hdf5"));
  EXPECT_EQ(s.get_string("output.dir"), "/tmp/x");
  EXPECT_EQ(s.get_string("mesh.shape"), "evans_fung");
  EXPECT_TRUE(s.was_set("cortex.nu"));
  EXPECT_FALSE(s.was_set("cortex.E_Pa"));
}

TEST(SceneParse, DottedKeysAndInlineTables) {
  const Scene s = Scene::from_string("mesh.radius_m = 2e-6\ntime = { dt_s = 1e-5 }\n", "t.toml");
  EXPECT_DOUBLE_EQ(s.get_real("mesh.radius_m"), 2e-6);
  EXPECT_DOUBLE_EQ(s.get_real("time.dt_s"), 1e-5);
}

TEST(SceneParse, LevenshteinSuggestion) {
  EXPECT_TRUE(contains(string_error("[cortex]\nk_bj = 1e-19\n"),
                       "unknown key 'cortex.k_bj' (did you mean 'cortex.k_b_J'?)"));
  EXPECT_TRUE(contains(string_error("[mesh]\nradius = 1e-6\n"), "(did you mean 'mesh.radius_m'?)"));
  EXPECT_TRUE(contains(string_error("nme = \"x\"\n"), "unknown key 'nme' (did you mean 'name'?)"));
  EXPECT_TRUE(contains(string_error("[mseh]\nradius_m = 1e-6\n"),
                       "unknown key 'mseh.radius_m' (did you mean 'mesh.radius_m'?)"));
}

TEST(SceneParse, UnknownKeyWithoutCloseMatchListsTheTable) {
  const std::string msg = string_error("[mesh]\ncompletely_different = 1\n");
  expect_one_line(msg);
  EXPECT_TRUE(
      contains(msg,
               "t.toml: unknown key 'mesh.completely_different' (known keys in [mesh]: shape, "
               "subdivisions, nodes, radius_m, diameter_m, refine_levels, refine_from_deg, refine_to_deg)"))
      << msg;
}

TEST(SceneParse, UnknownTable) {
  const std::string msg = string_error("[integrator]\ntolerance = 1e-9\n");
  expect_one_line(msg);
  EXPECT_TRUE(contains(msg, "unknown key 'integrator.tolerance'")) << msg;
  EXPECT_TRUE(
      contains(msg, "known tables: mesh, geometry, cortex, fluid, body, contact, time, solver, output"))
      << msg;
  const std::string empty = string_error("[integrator]\n");
  EXPECT_TRUE(contains(empty, "unknown table [integrator]")) << empty;
  EXPECT_TRUE(contains(string_error("[output]\nhdf5 = true\n[outptu]\n"), "(did you mean [output]?)"));
  EXPECT_TRUE(contains(string_error("[[runs]]\nx = 1\n"), "unknown key 'runs'"));
}

TEST(SceneParse, NestedTablesAndArraysRejected) {
  const std::string nested = string_error("[mesh.extra]\nfoo = 1\n");
  expect_one_line(nested);
  EXPECT_TRUE(contains(nested, "unknown key 'mesh.extra'")) << nested;
  EXPECT_TRUE(contains(string_error("[mesh]\nradius_m.x = 1\n"), "mesh.radius_m = {...} has the wrong type"));
  EXPECT_TRUE(contains(string_error("[[mesh]]\nshape = \"sphere\"\n"),
                       "has the wrong type: expected a table [mesh]"));
  EXPECT_TRUE(contains(string_error("[[mesh.layers]]\nx = 1\n"), "unknown key 'mesh.layers'"));
  EXPECT_TRUE(contains(string_error("mesh = 3\n"), "mesh = 3 has the wrong type: expected a table [mesh]"));
}

TEST(SceneParse, FirstErrorInFileOrder) {
  // toml++ sorts keys; the error reported is the first in the file, not alphabetically.
  const std::string msg = string_error("[mesh]\nzzz = 1\naaa = 2\n");
  EXPECT_TRUE(contains(msg, "'mesh.zzz'")) << msg;
}

TEST(SceneParse, IntegerAcceptedForReal) {
  const Scene s = Scene::from_string("[cortex]\nE_Pa = 800000\nx_max = 3\n", "t.toml");
  EXPECT_EQ(s.get_real("cortex.E_Pa"), 800000.0);
  EXPECT_EQ(s.get_real("cortex.x_max"), 3.0);
}

TEST(SceneParse, FloatRejectedForInt) {
  const std::string msg = string_error("[mesh]\nsubdivisions = 3.0\n");
  expect_one_line(msg);
  EXPECT_TRUE(contains(msg, "mesh.subdivisions = 3.0 has the wrong type: expected an integer")) << msg;
}

TEST(SceneParse, OtherWrongTypes) {
  EXPECT_TRUE(contains(string_error("[mesh]\nradius_m = \"big\"\n"),
                       "mesh.radius_m = \"big\" has the wrong type: expected a real number (m)"));
  EXPECT_TRUE(contains(string_error("[output]\nhdf5 = 1\n"),
                       "output.hdf5 = 1 has the wrong type: expected true or false"));
  EXPECT_TRUE(contains(string_error("[output]\nhdf5 = \"yes\"\n"), "expected true or false"));
  EXPECT_TRUE(
      contains(string_error("[mesh]\nshape = 1\n"), "mesh.shape = 1 has the wrong type: expected a string"));
  EXPECT_TRUE(
      contains(string_error("[mesh]\nradius_m = [1, 2]\n"), "has the wrong type: expected a real number"));
}

TEST(SceneParse, RangesAndChoices) {
  EXPECT_TRUE(
      contains(string_error("[cortex]\nnu = 0.6\n"), "cortex.nu = 0.6 is out of range: allowed 0 .. 0.5"));
  EXPECT_TRUE(contains(string_error("[cortex]\nE_Pa = 0\n"),
                       "cortex.E_Pa = 0 is out of range: allowed 1 .. 1000000000"));
  EXPECT_TRUE(contains(string_error("[cortex]\nx_max = 1\n"),
                       "cortex.x_max = 1 is out of range: allowed > 1 and ≤ 10"));
  EXPECT_NO_THROW(Scene::from_string("[cortex]\nnu = 0.5\n", "t.toml"));         // inclusive max
  EXPECT_NO_THROW(Scene::from_string("[cortex]\nc_N_s_per_m = 0\n", "t.toml"));  // inclusive min
  // H_min = 0 would make flat triangles' rounded spheres infinite: the clamp must be positive.
  EXPECT_TRUE(contains(string_error("[geometry]\nh_min_per_m = 0\n"),
                       "geometry.h_min_per_m = 0 is out of range: allowed > 0"));
  EXPECT_TRUE(contains(string_error("[mesh]\nshape = \"cube\"\n"),
                       "mesh.shape = \"cube\" is not allowed: choose one of sphere, evans_fung"));
  EXPECT_TRUE(
      contains(string_error("[mesh]\nnodes = 100\n"),
               "mesh.nodes = 100 is not allowed: choose one of 12, 42, 162, 642, 2562, 10242, 40962"));
}

TEST(SceneParse, NonFiniteRejected) {
  const std::string nan_msg = string_error("[cortex]\nE_Pa = nan\n");
  EXPECT_TRUE(contains(nan_msg, "cortex.E_Pa = nan is out of range: allowed 1 .. 1000000000")) << nan_msg;
  EXPECT_TRUE(contains(string_error("[time]\nt_end_s = inf\n"), "time.t_end_s = inf is out of range"));
  EXPECT_TRUE(contains(string_error("[cortex]\nk_a = -inf\n"), "cortex.k_a = -inf is out of range"));
  EXPECT_TRUE(contains(set_error("cortex.nu=nan"), "--set: cortex.nu = nan is out of range"));
}

TEST(SceneParse, RealsShownInShortestForm) {
  EXPECT_TRUE(
      contains(string_error("[cortex]\nnu = 0.5000000000000001\n"), "cortex.nu = 0.5000000000000001 is out"));
  // 0.55 is shown as 0.55, not 0.55000000000000004.
  EXPECT_TRUE(contains(string_error("[cortex]\nnu = 0.55\n"), "cortex.nu = 0.55 is out of range"));
}

// ---- mesh.nodes / mesh.subdivisions --------------------------------------------------------------

TEST(SceneMeshSize, OnlyNodesGiven) {
  const Scene s = Scene::from_string("[mesh]\nnodes = 642\n", "t.toml");
  EXPECT_EQ(s.get_int("mesh.nodes"), 642);
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 3);
  EXPECT_TRUE(s.was_set("mesh.nodes"));
  EXPECT_FALSE(s.was_set("mesh.subdivisions"));
}

TEST(SceneMeshSize, OnlySubdivisionsGiven) {
  const Scene s = Scene::from_string("[mesh]\nsubdivisions = 6\n", "t.toml");
  EXPECT_EQ(s.get_int("mesh.nodes"), 40962);
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 6);
  EXPECT_EQ(Scene::from_string("[mesh]\nsubdivisions = 0\n", "t.toml").get_int("mesh.nodes"), 12);
}

TEST(SceneMeshSize, BothConsistent) {
  const Scene s = Scene::from_string("[mesh]\nnodes = 162\nsubdivisions = 2\n", "t.toml");
  EXPECT_EQ(s.get_int("mesh.nodes"), 162);
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 2);
}

TEST(SceneMeshSize, BothDisagree) {
  const std::string msg = string_error("[mesh]\nnodes = 642\nsubdivisions = 4\n");
  expect_one_line(msg);
  EXPECT_TRUE(contains(msg, "mesh.nodes = 642")) << msg;
  EXPECT_TRUE(contains(msg, "mesh.subdivisions = 4")) << msg;
}

TEST(SceneMeshSize, SetOverridesTheOther) {
  Scene s = Scene::from_string("[mesh]\nnodes = 162\nsubdivisions = 2\n", "t.toml");
  s.set("mesh.subdivisions=5");
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 5);
  EXPECT_EQ(s.get_int("mesh.nodes"), 10242);
  EXPECT_TRUE(s.was_set("mesh.subdivisions"));
  EXPECT_FALSE(s.was_set("mesh.nodes"));
  s.set("mesh.subdivisions=1");  // the same key again: the last one counts
  EXPECT_EQ(s.get_int("mesh.nodes"), 42);
  s.set("mesh.nodes = 42");  // the other key, agreeing
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 1);
  EXPECT_EQ(s.get_int("mesh.nodes"), 42);
  EXPECT_TRUE(s.was_set("mesh.nodes"));
  EXPECT_FALSE(s.was_set("mesh.subdivisions"));
  // The result serialises to a consistent file.
  expect_same_values(Scene::from_string(s.to_toml(), "t.toml"), s);
}

// Two --set of the mesh size that disagree are refused, as the two keys in one file are (a user's
// `--set mesh.nodes=642 --set mesh.subdivisions=2` ran 162 nodes until session 39).
TEST(SceneMeshSize, TwoSetsMustAgree) {
  Scene s = Scene::defaults();
  s.set("mesh.nodes=642");
  try {
    s.set("mesh.subdivisions=2");
    FAIL() << "no error";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    expect_one_line(msg);
    EXPECT_TRUE(contains(msg, "mesh.nodes = 642 and mesh.subdivisions = 2 disagree")) << msg;
  }
  EXPECT_EQ(s.get_int("mesh.nodes"), 642);  // a refused set changes nothing
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 3);
  // Agreeing first does not let a later set of the same key drop the other one (found by review).
  s.set("mesh.subdivisions=3");
  EXPECT_THROW(s.set("mesh.subdivisions=2"), SceneError);
  EXPECT_EQ(s.get_int("mesh.nodes"), 642);
}

// ---- set() ---------------------------------------------------------------------------------------

TEST(SceneSet, ValuesInTomlSyntaxOrBareStrings) {
  Scene s = Scene::defaults();
  s.set("mesh.shape=evans_fung");
  s.set("mesh.radius_m=2.5e-6");
  s.set("cortex.E_Pa=1000000");
  s.set(" output.hdf5 = false ");
  s.set("output.dir=\"out/a b\"");
  s.set("name=run_12");
  EXPECT_EQ(s.get_string("mesh.shape"), "evans_fung");
  EXPECT_EQ(s.get_real("mesh.radius_m"), 2.5e-6);
  EXPECT_EQ(s.get_real("cortex.E_Pa"), 1e6);
  EXPECT_FALSE(s.get_bool("output.hdf5"));
  EXPECT_EQ(s.get_string("output.dir"), "out/a b");
  EXPECT_EQ(s.name(), "run_12");
  EXPECT_TRUE(s.was_set("mesh.radius_m"));
  s.set("output.dir=/abs/path=1");  // bare text, everything after the first '='
  EXPECT_EQ(s.get_string("output.dir"), "/abs/path=1");
  s.set("name=2024");  // a TOML integer, but name is a string: the text is taken
  EXPECT_EQ(s.name(), "2024");
}

TEST(SceneSet, Errors) {
  EXPECT_EQ(set_error("xyz"), "--set: expected key=value, got 'xyz'");
  EXPECT_EQ(set_error("mesh.radus_m=1e-6"),
            "--set: unknown key 'mesh.radus_m' (did you mean 'mesh.radius_m'?)");
  EXPECT_EQ(set_error("mesh.subdivisions=9"), "--set: mesh.subdivisions = 9 is out of range: allowed 0 .. 6");
  EXPECT_EQ(set_error("mesh.subdivisions=four"),
            "--set: mesh.subdivisions = four has the wrong type: expected an integer");
  EXPECT_EQ(set_error("mesh.subdivisions=3.0"),
            "--set: mesh.subdivisions = 3.0 has the wrong type: expected an integer");
  EXPECT_EQ(set_error("mesh.shape=cube"),
            "--set: mesh.shape = \"cube\" is not allowed: choose one of sphere, evans_fung");
  EXPECT_EQ(set_error("output.hdf5=yes"),
            "--set: output.hdf5 = yes has the wrong type: expected true or false");
  EXPECT_EQ(set_error("mesh.radius_m=-1e-6"),
            "--set: mesh.radius_m = -1e-06 is out of range: allowed > 0 and ≤ 0.001");
  expect_one_line(set_error("mesh.subdivisions=1\nmesh.nodes=12"));
}

TEST(SceneSet, FailedSetLeavesTheSceneUnchanged) {
  Scene s = Scene::defaults();
  EXPECT_THROW(s.set("mesh.subdivisions=9"), SceneError);
  EXPECT_EQ(s.get_int("mesh.subdivisions"), 4);
  EXPECT_FALSE(s.was_set("mesh.subdivisions"));
}

// ---- cross-key validation ------------------------------------------------------------------------

TEST(SceneValidate, RefinedBandEndsAboveItsStart) {
  const std::string msg =
      string_error("[mesh]\nrefine_levels = 2\nrefine_from_deg = 90\nrefine_to_deg = 80\n");
  expect_one_line(msg);
  EXPECT_EQ(msg,
            "t.toml: mesh.refine_to_deg = 80 is not allowed: the refined band must end above "
            "mesh.refine_from_deg = 90");
  // Without refinement the band is not read.
  Scene s = Scene::defaults();
  s.set("mesh.refine_from_deg=90");
  s.set("mesh.refine_to_deg=80");
  EXPECT_NO_THROW(s.validate());
}

TEST(SceneValidate, H0BelowCellRadius) {
  const std::string msg = string_error("[contact]\nh0_m = 5e-7\n[mesh]\nradius_m = 4e-7\n");
  expect_one_line(msg);
  EXPECT_EQ(msg, "t.toml: contact.h0_m = 5e-07 must be smaller than the cell radius mesh.radius_m = 4e-07");
  const std::string ef = string_error(
      "[contact]\nh0_m = 5e-7\n[mesh]\nshape = \"evans_fung\"\ndiameter_m = 8e-7\nradius_m = 1e-6\n");
  EXPECT_TRUE(contains(ef, "must be smaller than the cell radius mesh.diameter_m/2 = 4e-07")) << ef;

  Scene s = Scene::defaults();
  s.set("mesh.radius_m=1e-8");
  // The value came from --set, not from the defaults: the message says so.
  try {
    s.validate();
    ADD_FAILURE() << "a 10-nm cell with h0 = 20 nm validated";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--set: contact.h0_m = ", 0), 0U) << e.what();
  }
  s.set("mesh.radius_m=1e-6");
  EXPECT_NO_THROW(s.validate());
  Scene named = Scene::defaults();
  named.set("name=a/b");
  try {
    named.validate();
    ADD_FAILURE() << "a name with a path validated";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--set: name = 'a/b' is not allowed", 0), 0U) << e.what();
  }
}

// ---- output --------------------------------------------------------------------------------------

TEST(SceneToToml, RoundTrips) {
  Scene s = Scene::from_file(source_path("scenes/evans_fung.toml"));
  s.set("cortex.nu=0.1");
  s.set("mesh.radius_m=3.3333333333333333e-6");
  s.set("contact.W_J_per_m2=0.00123456789012345678");
  s.set("output.dir=\"quote\\\" back\\\\slash\"");
  s.set("output.hdf5=false");
  s.set("mesh.subdivisions=2");
  const std::string text = s.to_toml();
  const Scene back = Scene::from_string(text, "round.toml");
  expect_same_values(back, s);
  EXPECT_EQ(back.get_string("output.dir"), "quote\" back\\slash");
  EXPECT_EQ(back.to_toml().substr(back.to_toml().find('\n')), text.substr(text.find('\n')));
  EXPECT_TRUE(contains(text, "\n[mesh]\n")) << text;
  EXPECT_TRUE(contains(text, "\nradius_m = ")) << text;
  EXPECT_TRUE(contains(text, "# m — ")) << text;
  EXPECT_TRUE(contains(text, "name = \"evans_fung\"")) << text;
  EXPECT_LT(text.find("[mesh]"), text.find("[cortex]"));
  EXPECT_LT(text.find("[cortex]"), text.find("[output]"));
}

TEST(SceneToToml, DefaultsRoundTrip) {
  const Scene d = Scene::defaults();
  const Scene back = Scene::from_string(d.to_toml(), "x.toml");
  expect_same_values(back, d);
}

TEST(SceneSchemaMarkdown, OneTablePerSection) {
  const std::string md = scene_schema_markdown();
  for (const char* heading : {"## [mesh]", "## [geometry]", "## [cortex]", "## [fluid]", "## [contact]",
                              "## [time]", "## [output]"}) {
    EXPECT_TRUE(contains(md, heading)) << heading;
  }
  size_t headers = 0;
  for (size_t pos = 0;
       (pos = md.find("| key | type | default | allowed | unit | meaning |", pos)) != std::string::npos;
       ++pos) {
    ++headers;
  }
  EXPECT_EQ(headers, 10u);  // top level + 9 tables
  EXPECT_TRUE(contains(md, "| `mesh.subdivisions` | integer | `4` | 0 .. 6 |")) << md;
  EXPECT_TRUE(contains(md, "| `mesh.radius_m` | real | `3.25e-6` | > 0 and ≤ 0.001 | m |")) << md;
  EXPECT_TRUE(contains(md, "| `mesh.shape` | string | `\"sphere\"` | sphere, evans_fung |")) << md;
}

}  // namespace
}  // namespace dcm
