// A seeded random-mutation fuzzer for the scene parser (issue 8): mutated scene files and --set arguments
// must either parse, and then round-trip through to_toml(), or be rejected with a one-line SceneError.
// Any other exception, a crash or a hang (the ctest timeout) is a failure. Bounded by input count and wall
// time: DCM_FUZZ_INPUTS (default 20000) and DCM_FUZZ_SECONDS (default 60); DCM_FUZZ_SEED picks the stream.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "dcm_config.hpp"

namespace {

namespace fs = std::filesystem;
using dcm::Scene;
using dcm::SceneError;

std::vector<std::string> corpus() {
  std::vector<std::string> out;
  for (const char* dir : {DCM_SOURCE_DIR "/scenes", DCM_SOURCE_DIR "/tests/scenes"}) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".toml") continue;
      std::ifstream f(entry.path());
      std::stringstream ss;
      ss << f.rdbuf();
      out.push_back(ss.str());
    }
  }
  out.push_back(Scene::defaults().to_toml());
  return out;
}

// Pieces of TOML and of the schema's vocabulary that random bytes would rarely hit.
const std::vector<std::string> kTokens = {"=",
                                          "[",
                                          "]",
                                          "[[",
                                          "]]",
                                          "\"",
                                          "'",
                                          "'''",
                                          "\"\"\"",
                                          "\n",
                                          "#",
                                          ".",
                                          ",",
                                          "{",
                                          "}",
                                          "-",
                                          "+",
                                          "_",
                                          "0",
                                          "1e999",
                                          "-1e999",
                                          "nan",
                                          "inf",
                                          "-inf",
                                          "1e-320",
                                          "0x1F",
                                          "0b101",
                                          "true",
                                          "false",
                                          "1979-05-27T07:32:00Z",
                                          "9223372036854775807",
                                          "99999999999999999999",
                                          "mesh",
                                          "cortex",
                                          "contact",
                                          "time",
                                          "output",
                                          "solver",
                                          "radius_m",
                                          "nodes",
                                          "\\u0000",
                                          "\\",
                                          "\xc3\xa9",
                                          "\xff\xfe",
                                          "\x00",
                                          "\t",
                                          "\r\n",
                                          "mesh.nodes = 642",
                                          "[mesh]\nshape = \"sphere\"\n",
                                          "x_max = 1",
                                          "h0_m = 1",
                                          "t_end_s = -1"};

std::string mutate(std::string s, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return n == 0 ? std::size_t{0} : static_cast<std::size_t>(rng() % n); };
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = pick(s.size() + 1);
    switch (rng() % 8) {
      case 0:  // flip a byte
        if (!s.empty()) s[pick(s.size())] = static_cast<char>(rng() & 0xff);
        break;
      case 1:  // insert a token
        s.insert(at, kTokens[pick(kTokens.size())]);
        break;
      case 2:  // delete a span
        if (at < s.size()) s.erase(at, 1 + pick(16));
        break;
      case 3: {  // duplicate a line
        const std::size_t begin = s.rfind('\n', at == 0 ? 0 : at - 1);
        const std::size_t from = begin == std::string::npos ? 0 : begin + 1;
        const std::size_t end = s.find('\n', from);
        s.insert(from, s.substr(from, end == std::string::npos ? std::string::npos : end - from + 1));
        break;
      }
      case 4: {  // replace the value after an '=' by a token
        const std::size_t eq = s.find('=', at);
        if (eq == std::string::npos) break;
        const std::size_t end = s.find('\n', eq);
        s.replace(eq + 1, end == std::string::npos ? std::string::npos : end - eq - 1,
                  " " + kTokens[pick(kTokens.size())]);
        break;
      }
      case 5:  // truncate
        s.resize(at);
        break;
      case 6:  // a random byte
        s.insert(at, 1, static_cast<char>(rng() & 0xff));
        break;
      default: {  // swap two characters
        if (s.size() > 1) std::swap(s[pick(s.size())], s[pick(s.size())]);
      }
    }
  }
  return s;
}

long env_or(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v ? std::strtol(v, nullptr, 10) : fallback;
}

TEST(SceneFuzz, MutatedScenesParseOrFailWithOneLine) {
  const std::vector<std::string> seeds = corpus();
  ASSERT_GE(seeds.size(), 8u);
  const long max_inputs = env_or("DCM_FUZZ_INPUTS", 20000), max_seconds = env_or("DCM_FUZZ_SECONDS", 60);
  const auto seed = static_cast<std::uint64_t>(env_or("DCM_FUZZ_SEED", 20261130));
  std::mt19937_64 rng(seed);
  const auto t0 = std::chrono::steady_clock::now();
  long tried = 0, accepted = 0, rejected = 0;
  for (; tried < max_inputs; ++tried) {
    if (tried % 256 == 0 && std::chrono::steady_clock::now() - t0 > std::chrono::seconds(max_seconds)) break;
    const std::string input = mutate(seeds[static_cast<std::size_t>(rng() % seeds.size())], rng);
    try {
      const Scene s = Scene::from_string(input, "fuzz.toml");
      ++accepted;
      // What parsed must write itself back and parse again to the same scene.
      const std::string text = s.to_toml();
      const Scene again = Scene::from_string(text, "fuzz.toml");
      ASSERT_EQ(again.to_toml(), text) << "input #" << tried << " (seed " << seed << "):\n" << input;
    } catch (const SceneError& e) {
      ++rejected;
      const std::string what = e.what();
      ASSERT_EQ(what.find('\n'), std::string::npos)
          << "multi-line error for input #" << tried << ": " << what;
      ASSERT_EQ(what.rfind("fuzz.toml", 0), 0u) << "error without the file name: " << what;
    } catch (const std::exception& e) {
      FAIL() << "input #" << tried << " (seed " << seed << ") threw " << typeid(e).name() << ": " << e.what()
             << "\n--- input ---\n"
             << input;
    }
  }
  std::printf("scene fuzz: %ld inputs (seed %llu): %ld accepted, %ld rejected with one line\n", tried,
              static_cast<unsigned long long>(seed), accepted, rejected);
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, tried / 4);
}

TEST(SceneFuzz, RandomSetArgumentsAreAppliedOrRejectedWithOneLine) {
  std::mt19937_64 rng(static_cast<std::uint64_t>(env_or("DCM_FUZZ_SEED", 20261130)) + 1);
  const std::vector<dcm::ParamSpec>& schema = dcm::scene_schema();
  const long max_inputs = env_or("DCM_FUZZ_INPUTS", 20000);
  long tried = 0, applied = 0;
  for (; tried < max_inputs; ++tried) {
    Scene s = Scene::defaults();
    const std::string before = s.to_toml();
    std::string arg = schema[static_cast<std::size_t>(rng() % schema.size())].key + "=" +
                      kTokens[static_cast<std::size_t>(rng() % kTokens.size())];
    arg = mutate(arg, rng);
    try {
      s.set(arg);
      s.validate();
      ++applied;
    } catch (const SceneError& e) {
      ASSERT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    } catch (const std::exception& e) {
      FAIL() << "--set '" << arg << "' threw " << e.what();
    }
  }
  std::printf("--set fuzz: %ld arguments, %ld applied\n", tried, applied);
  EXPECT_GT(applied, 0);
}

}  // namespace
