#pragma once
// HDF5 output of a run with an XDMF companion that ParaView opens.
//
// File layout (all datasets double unless said):
//   /                       attributes: "dcm_version", and any write_text() entries (e.g. "scene")
//   /mesh/x                 [n_nodes][3] reference positions (m)
//   /mesh/triangles         [n_tris][3]  int32, outward oriented, 0-based
//   /mesh/node_cell         [n_nodes]    int32, cell index of each node
//   /frames/<6 digits>/x    [n_nodes][3] positions (m); attribute "time" (s)
//   /frames/<6 digits>/<f>  [n_nodes] or [n_nodes][3] per-node field
//   /series/<name>          [n_rows] extendible, chunked; one dataset per column of append_series()
//   /meta/<name>            scalar datasets from write_scalar()
// The XDMF file (written beside, same stem, ".xmf") is a temporal collection of one grid per frame
// referencing the datasets above; with no frame written it holds one static grid of /mesh/x.
// It is rewritten (temporary file + rename) after every frame, and the HDF5 file is flushed, so a run
// killed between frames leaves both files readable.
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.hpp"  // IoError

namespace dcm {

struct NodeField {
  std::string name;
  int components;      // 1 or 3
  const double* data;  // host, n_nodes * components, row major
};

class H5Output {
 public:
  // Creates (truncates) h5_path; the XDMF goes to the same path with extension ".xmf".
  explicit H5Output(const std::string& h5_path);
  // Continues the file of an earlier run (a restart from a checkpoint): keeps its mesh and its first
  // keep_frames frames, deletes later frames and the whole series (the caller appends the rows again).
  // Throws IoError if the file is missing, has fewer frames, or was not written by H5Output.
  struct Resume {
    int keep_frames;
  };
  H5Output(const std::string& h5_path, Resume resume);
  ~H5Output();  // closes; never throws
  H5Output(const H5Output&) = delete;
  H5Output& operator=(const H5Output&) = delete;

  void write_text(const std::string& name, const std::string& text);  // root string attribute
  void write_scalar(const std::string& name, double value);           // /meta/<name>
  void write_mesh(const double* x, int n_nodes, const int* triangles, int n_tris, const int* node_cell);
  // Returns the frame index. Requires write_mesh() first.
  int write_frame(double time, const double* x, const std::vector<NodeField>& fields);
  // One row of named scalars; the column set is fixed by the first call.
  void append_series(const std::vector<std::pair<std::string, double>>& row);
  void flush();
  void close();
  int frames() const;  // frames in the file

  const std::string& h5_path() const { return h5_path_; }
  const std::string& xdmf_path() const { return xdmf_path_; }

 private:
  struct Impl;
  Impl* impl_;
  std::string h5_path_, xdmf_path_;
};

}  // namespace dcm
