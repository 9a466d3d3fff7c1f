#pragma once
// A checkpoint: the complete state of a run at a step boundary, as named arrays of doubles and named texts,
// so that a restarted run continues bit for bit (docs/CHECKPOINTS.md). The model, the time stepper and the
// app each put their own entries ("model.x", "stepper.t", "app.step", ...); the file format is theirs to
// extend. Plain data here; the HDF5 file is written by write_checkpoint() (dcm_io, core/checkpoint.cpp).
//
// File layout: root attribute "format" = "dcm-checkpoint-3"; /arrays/<name> 1-D double datasets;
// /texts/<name> variable-length UTF-8 string datasets.
#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/errors.hpp"  // IoError

namespace dcm {

struct Checkpoint {
  std::map<std::string, std::vector<double>> arrays;
  std::map<std::string, std::string> texts;
  std::string origin = "checkpoint";  // the file it was read from, for messages

  void put(const std::string& name, double value) { arrays[name] = {value}; }
  void put(const std::string& name, std::vector<double> values) { arrays[name] = std::move(values); }
  void put_text(const std::string& name, std::string text) { texts[name] = std::move(text); }

  // The array `name`; with expected_size > 0 its length must match. Throws IoError naming the file.
  const std::vector<double>& array(const std::string& name, std::size_t expected_size = 0) const {
    const auto it = arrays.find(name);
    if (it == arrays.end()) throw IoError(origin + ": not a complete dcm checkpoint (no '" + name + "')");
    if (expected_size > 0 && it->second.size() != expected_size)
      throw IoError(origin + ": '" + name + "' holds " + std::to_string(it->second.size()) +
                    " values, this run needs " + std::to_string(expected_size) +
                    " (a checkpoint of another mesh?)");
    return it->second;
  }
  double scalar(const std::string& name) const { return array(name, 1)[0]; }
  const std::string& text(const std::string& name) const {
    const auto it = texts.find(name);
    if (it == texts.end()) throw IoError(origin + ": not a complete dcm checkpoint (no '" + name + "')");
    return it->second;
  }
};

// Writes `path` atomically: a temporary file beside it ("<path>.tmp"), flushed and closed, then renamed over
// `path`; a crash leaves either the old checkpoint or the new one. Throws IoError.
void write_checkpoint(const std::string& path, const Checkpoint& checkpoint);

// Throws IoError (one line naming the file) if it is missing, unreadable or not a dcm checkpoint.
Checkpoint read_checkpoint(const std::string& path);

}  // namespace dcm
