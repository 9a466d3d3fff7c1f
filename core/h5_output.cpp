#include "core/h5_output.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "core/h5_links.hpp"
#include "dcm_config.hpp"  // DCM_VERSION

namespace dcm {
namespace {

namespace fs = std::filesystem;

constexpr hsize_t k_series_chunk = 1024;

// Owns one HDF5 identifier and closes it with the matching H5?close function.
class Hid {
 public:
  using Closer = herr_t (*)(hid_t);
  Hid() = default;
  Hid(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Hid() { reset(); }
  Hid(Hid&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = H5I_INVALID_HID; }
  Hid& operator=(Hid&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = other.id_;
      closer_ = other.closer_;
      other.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now; returns the closer's status (0 when nothing was open).
  herr_t reset() noexcept {
    herr_t status = 0;
    if (id_ >= 0 && closer_ != nullptr) status = closer_(id_);
    id_ = H5I_INVALID_HID;
    return status;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

struct FieldInfo {
  std::string name;
  int components;
};

void check_name(const std::string& name, const char* what) {
  if (name.empty() || name == "." || name.find('/') != std::string::npos) {
    throw std::invalid_argument(std::string("H5Output: ") + what + " name '" + name +
                                "' is invalid (must be non-empty, not '.', without '/')");
  }
}

std::string xml_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string format_double(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string frame_group_name(int index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "/frames/%06d", index);
  return buf;
}

// Why H5Fcreate most likely failed; HDF5's own stack is silenced.
std::string create_failure_reason(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) return "folder does not exist";
  if (fs::is_directory(path, ec)) return "path is a folder";
  return "permission denied, or the file is open in another program";
}

}  // namespace

struct H5Output::Impl {
  std::string path;     // for messages
  std::string h5_name;  // basename, as the XDMF references it
  std::string xdmf_path;
  Hid file;
  bool closed = false;
  bool has_mesh = false;
  int n_nodes = 0, n_tris = 0;
  int n_frames = 0;
  std::string frames_xml;  // one <Grid> per frame, appended as frames are written
  std::vector<std::string> series_columns;
  std::vector<Hid> series_sets;
  hsize_t series_rows = 0;

  [[noreturn]] void fail(const std::string& what) const { throw IoError(path + ": " + what); }
  hid_t checked(hid_t id, const std::string& what) const {
    if (id < 0) fail(what);
    return id;
  }
  void checked(herr_t status, const std::string& what) const {
    if (status < 0) fail(what);
  }
  Hid make(hid_t id, Hid::Closer closer, const std::string& what) const {
    return Hid(checked(id, what), closer);
  }

  void require_open() const {
    if (closed) throw std::logic_error("H5Output: " + path + " is already closed");
  }

  bool link_exists(const std::string& name) const {
    const htri_t r = H5Lexists(file.get(), name.c_str(), H5P_DEFAULT);
    if (r < 0) fail("cannot look up " + name);
    return r > 0;
  }

  void ensure_group(const std::string& name) const {
    if (link_exists(name)) return;
    make(H5Gcreate2(file.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
         "cannot create group " + name);
  }

  // Writes a fixed-size dataset of `rank` dims; `file_type` is the stored type, `mem_type` the buffer's.
  void write_dataset(hid_t loc, const std::string& name, const std::string& full_name, int rank,
                     const hsize_t* dims, hid_t file_type, hid_t mem_type, const void* data) const {
    const hid_t space_id = rank == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(rank, dims, nullptr);
    Hid space = make(space_id, H5Sclose, "cannot create dataspace for " + full_name);
    Hid set =
        make(H5Dcreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose, "cannot create dataset " + full_name);
    checked(H5Dwrite(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
            "cannot write dataset " + full_name);
  }

  void write_double_attribute(hid_t loc, const std::string& name, double value,
                              const std::string& owner) const {
    Hid space = make(H5Screate(H5S_SCALAR), H5Sclose, "cannot create dataspace for attribute " + name);
    Hid attr = make(H5Acreate2(loc, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                    H5Aclose, "cannot create attribute " + name + " on " + owner);
    checked(H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, &value),
            "cannot write attribute " + name + " on " + owner);
  }

  void write_string_attribute(const std::string& name, const std::string& text) const {
    const htri_t exists = H5Aexists(file.get(), name.c_str());
    if (exists < 0) fail("cannot look up attribute " + name);
    if (exists > 0) checked(H5Adelete(file.get(), name.c_str()), "cannot replace attribute " + name);
    Hid type = make(H5Tcopy(H5T_C_S1), H5Tclose, "cannot create string type");
    checked(H5Tset_size(type.get(), H5T_VARIABLE), "cannot create string type");
    checked(H5Tset_cset(type.get(), H5T_CSET_UTF8), "cannot create string type");
    Hid space = make(H5Screate(H5S_SCALAR), H5Sclose, "cannot create dataspace for attribute " + name);
    Hid attr = make(H5Acreate2(file.get(), name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                    H5Aclose, "cannot create attribute " + name);
    const char* ptr = text.c_str();
    checked(H5Awrite(attr.get(), type.get(), &ptr), "cannot write attribute " + name);
  }

  void create_series(const std::vector<std::pair<std::string, double>>& row) {
    ensure_group("/series");
    const hsize_t dims[1] = {0}, max_dims[1] = {H5S_UNLIMITED}, chunk[1] = {k_series_chunk};
    Hid props = make(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "cannot create dataset properties");
    checked(H5Pset_chunk(props.get(), 1, chunk), "cannot set chunking for /series");
    Hid space = make(H5Screate_simple(1, dims, max_dims), H5Sclose, "cannot create dataspace for /series");
    std::vector<std::string> columns;
    std::vector<Hid> sets;
    for (const auto& column : row) {
      const std::string name = "/series/" + column.first;
      sets.push_back(make(H5Dcreate2(file.get(), name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                     props.get(), H5P_DEFAULT),
                          H5Dclose, "cannot create dataset " + name));
      columns.push_back(column.first);
    }
    series_columns = std::move(columns);  // only once every column exists
    series_sets = std::move(sets);
  }

  void append_value(hid_t set, const std::string& column, double value) const {
    const std::string name = "/series/" + column;
    const hsize_t new_size[1] = {series_rows + 1}, start[1] = {series_rows}, count[1] = {1};
    checked(H5Dset_extent(set, new_size), "cannot extend dataset " + name);
    Hid file_space = make(H5Dget_space(set), H5Sclose, "cannot get dataspace of " + name);
    checked(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr),
            "cannot select row in " + name);
    Hid mem_space =
        make(H5Screate_simple(1, count, nullptr), H5Sclose, "cannot create dataspace for " + name);
    checked(H5Dwrite(set, H5T_NATIVE_DOUBLE, mem_space.get(), file_space.get(), H5P_DEFAULT, &value),
            "cannot write dataset " + name);
  }

  std::string data_item(const std::string& dataset, const std::string& dims, bool is_int) const {
    return std::string("<DataItem Format=\"HDF\" NumberType=\"") +
           (is_int ? "Int\" Precision=\"4\"" : "Float\" Precision=\"8\"") + " Dimensions=\"" + dims + "\">" +
           xml_escape(h5_name) + ":" + dataset + "</DataItem>";
  }

  std::string attribute_xml(const std::string& name, const std::string& dataset, int components,
                            bool is_int) const {
    const std::string n = std::to_string(n_nodes);
    return "        <Attribute Name=\"" + xml_escape(name) + "\" AttributeType=\"" +
           (components == 3 ? "Vector" : "Scalar") + "\" Center=\"Node\">\n          " +
           data_item(xml_escape(dataset), components == 3 ? n + " 3" : n, is_int) +
           "\n        </Attribute>\n";
  }

  // One Uniform grid; `time` is written only for frames.
  std::string grid_xml(const std::string& grid_name, const std::string& x_dataset, const std::string* time,
                       const std::string& attributes) const {
    std::string s = "      <Grid Name=\"" + grid_name + "\" GridType=\"Uniform\">\n";
    if (time != nullptr) s += "        <Time Value=\"" + *time + "\"/>\n";
    s += "        <Topology TopologyType=\"Triangle\" NumberOfElements=\"" + std::to_string(n_tris) + "\">\n";
    s += "          " + data_item("/mesh/triangles", std::to_string(n_tris) + " 3", true) + "\n";
    s += "        </Topology>\n        <Geometry GeometryType=\"XYZ\">\n";
    s += "          " + data_item(x_dataset, std::to_string(n_nodes) + " 3", false) + "\n";
    s += "        </Geometry>\n";
    s += attribute_xml("node_cell", "/mesh/node_cell", 1, true);
    return s + attributes + "      </Grid>\n";
  }

  std::string xdmf_text() const {
    std::string s = "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n";
    if (n_frames == 0) {
      s += grid_xml("mesh", "/mesh/x", nullptr, "");
    } else {
      s += "    <Grid Name=\"frames\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
      s += frames_xml;
      s += "    </Grid>\n";
    }
    return s + "  </Domain>\n</Xdmf>\n";
  }

  // Temporary file in the same folder, then rename over the old one: readers never see half a file.
  void write_xdmf() const {
    const std::string tmp = xdmf_path + ".tmp";
    const std::string text = xdmf_text();
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (f == nullptr) throw IoError(tmp + ": cannot create file (permission denied or missing folder)");
    const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    const bool closed_ok = std::fclose(f) == 0;
    if (!written || !closed_ok) {
      std::remove(tmp.c_str());
      throw IoError(tmp + ": cannot write file (disk full?)");
    }
    if (std::rename(tmp.c_str(), xdmf_path.c_str()) != 0) {
      std::remove(tmp.c_str());
      throw IoError(xdmf_path + ": cannot replace file with " + tmp);
    }
  }
};

H5Output::H5Output(const std::string& h5_path) : impl_(nullptr), h5_path_(h5_path) {
  if (fs::path(h5_path).extension() == ".xmf") {
    throw std::invalid_argument("H5Output: " + h5_path + ": the HDF5 path must not end in .xmf");
  }
  xdmf_path_ = fs::path(h5_path).replace_extension(".xmf").string();
  auto impl = std::make_unique<Impl>();
  impl->path = h5_path;
  impl->h5_name = fs::path(h5_path).filename().string();
  impl->xdmf_path = xdmf_path_;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // we report errors ourselves, in one line
  const hid_t id = H5Fcreate(h5_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (id < 0) impl->fail("cannot create file (" + create_failure_reason(h5_path) + ")");
  impl->file = Hid(id, H5Fclose);
  impl->write_string_attribute("dcm_version", DCM_VERSION);
  impl_ = impl.release();
}

namespace {

// Dimensions of a dataset (empty if it cannot be read).
std::vector<hsize_t> dataset_dims(hid_t loc, const std::string& name) {
  const hid_t set = H5Dopen2(loc, name.c_str(), H5P_DEFAULT);
  if (set < 0) return {};
  const hid_t space = H5Dget_space(set);
  std::vector<hsize_t> dims;
  const int rank = space < 0 ? -1 : H5Sget_simple_extent_ndims(space);
  if (rank > 0) {
    dims.resize(static_cast<std::size_t>(rank));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  }
  if (space >= 0) H5Sclose(space);
  H5Dclose(set);
  return dims;
}

}  // namespace

H5Output::H5Output(const std::string& h5_path, Resume resume) : impl_(nullptr), h5_path_(h5_path) {
  xdmf_path_ = fs::path(h5_path).replace_extension(".xmf").string();
  auto impl = std::make_unique<Impl>();
  impl->path = h5_path;
  impl->h5_name = fs::path(h5_path).filename().string();
  impl->xdmf_path = xdmf_path_;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  std::error_code ec;
  if (!fs::is_regular_file(h5_path, ec))
    impl->fail(
        "cannot continue: the file of the run is missing (a checkpoint continues in its run's folder, beside "
        "the "
        "run's HDF5 file: copy the folder, not the checkpoint alone)");
  const hid_t id = H5Fopen(h5_path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  if (id < 0) impl->fail("cannot continue the file (" + create_failure_reason(h5_path) + ")");
  Impl& m = *impl;
  m.file = Hid(id, H5Fclose);
  const std::vector<hsize_t> x = dataset_dims(id, "/mesh/x"), tris = dataset_dims(id, "/mesh/triangles");
  if (x.size() != 2 || tris.size() != 2 || !m.link_exists("/frames"))
    m.fail("cannot continue: not a file written by dcm (no /mesh or /frames)");
  m.n_nodes = static_cast<int>(x[0]);
  m.n_tris = static_cast<int>(tris[0]);
  m.has_mesh = true;
  Hid frames = m.make(H5Gopen2(id, "/frames", H5P_DEFAULT), H5Gclose, "cannot open /frames");
  const std::vector<std::string> names = detail::h5_link_names(frames.get());
  if (static_cast<int>(names.size()) < resume.keep_frames)
    m.fail("cannot continue: it holds " + std::to_string(names.size()) + " frames, the checkpoint " +
           std::to_string(resume.keep_frames));
  for (int i = 0; i < static_cast<int>(names.size()); ++i) {
    const std::string group_name = frame_group_name(i);
    if (i >= resume.keep_frames) {
      m.checked(H5Ldelete(id, group_name.c_str(), H5P_DEFAULT), "cannot delete " + group_name);
      continue;
    }
    Hid group = m.make(H5Gopen2(id, group_name.c_str(), H5P_DEFAULT), H5Gclose, "cannot open " + group_name);
    double time = 0;
    {
      Hid attr = m.make(H5Aopen(group.get(), "time", H5P_DEFAULT), H5Aclose, "no time on " + group_name);
      m.checked(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &time), "cannot read the time of " + group_name);
    }
    std::string attributes;
    for (const std::string& field : detail::h5_link_names(group.get())) {
      if (field == "x") continue;
      const std::vector<hsize_t> dims = dataset_dims(group.get(), field);
      const int components = dims.size() == 2 ? static_cast<int>(dims[1]) : 1;
      attributes += m.attribute_xml(field, group_name + "/" + field, components, false);
    }
    const std::string time_text = format_double(time);
    m.frames_xml += m.grid_xml("frame_" + group_name.substr(8), group_name + "/x", &time_text, attributes);
  }
  m.n_frames = resume.keep_frames;
  if (m.link_exists("/series")) m.checked(H5Ldelete(id, "/series", H5P_DEFAULT), "cannot reset /series");
  m.checked(H5Fflush(id, H5F_SCOPE_LOCAL), "cannot flush file");
  m.write_xdmf();
  impl_ = impl.release();
}

int H5Output::frames() const { return impl_->n_frames; }

H5Output::~H5Output() {
  try {
    close();
  } catch (const std::exception& e) {
    std::cerr << "dcm: warning: " << e.what() << "\n";
  } catch (...) {
  }
  delete impl_;
}

void H5Output::write_text(const std::string& name, const std::string& text) {
  impl_->require_open();
  check_name(name, "text attribute");
  impl_->write_string_attribute(name, text);
}

void H5Output::write_scalar(const std::string& name, double value) {
  impl_->require_open();
  check_name(name, "scalar");
  impl_->ensure_group("/meta");
  const std::string full = "/meta/" + name;
  if (impl_->link_exists(full)) {
    impl_->checked(H5Ldelete(impl_->file.get(), full.c_str(), H5P_DEFAULT), "cannot replace " + full);
  }
  impl_->write_dataset(impl_->file.get(), full, full, 0, nullptr, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

void H5Output::write_mesh(const double* x, int n_nodes, const int* triangles, int n_tris,
                          const int* node_cell) {
  Impl& m = *impl_;
  m.require_open();
  if (m.has_mesh) throw std::logic_error("H5Output: " + m.path + ": write_mesh() called twice");
  if (n_nodes <= 0 || n_tris < 0 || x == nullptr || node_cell == nullptr ||
      (n_tris > 0 && triangles == nullptr)) {
    throw std::invalid_argument("H5Output: write_mesh() needs n_nodes > 0, n_tris >= 0 and non-null arrays");
  }
  const auto n_corners = static_cast<std::size_t>(n_tris) * 3;
  const auto bad =
      std::find_if(triangles, triangles + n_corners, [&](int v) { return v < 0 || v >= n_nodes; });
  if (bad != triangles + n_corners) {
    throw std::invalid_argument("H5Output: write_mesh(): triangle corner " + std::to_string(*bad) +
                                " is not a node index in [0, " + std::to_string(n_nodes) + ")");
  }
  const hsize_t nodes[2] = {static_cast<hsize_t>(n_nodes), 3}, tris[2] = {static_cast<hsize_t>(n_tris), 3};
  m.ensure_group("/mesh");
  const hid_t f = m.file.get();
  m.write_dataset(f, "/mesh/x", "/mesh/x", 2, nodes, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, x);
  m.write_dataset(f, "/mesh/triangles", "/mesh/triangles", 2, tris, H5T_STD_I32LE, H5T_NATIVE_INT, triangles);
  m.write_dataset(f, "/mesh/node_cell", "/mesh/node_cell", 1, nodes, H5T_STD_I32LE, H5T_NATIVE_INT,
                  node_cell);
  m.ensure_group("/frames");
  m.n_nodes = n_nodes;
  m.n_tris = n_tris;
  m.has_mesh = true;
  m.checked(H5Fflush(f, H5F_SCOPE_LOCAL), "cannot flush file");
  m.write_xdmf();
}

namespace {

void check_fields(const std::vector<NodeField>& fields) {
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const NodeField& f = fields[i];
    check_name(f.name, "field");
    if (f.name == "x") throw std::invalid_argument("H5Output: field name 'x' is reserved for positions");
    if (f.components != 1 && f.components != 3) {
      throw std::invalid_argument("H5Output: field '" + f.name + "' has " + std::to_string(f.components) +
                                  " components; allowed: 1 or 3");
    }
    if (f.data == nullptr) throw std::invalid_argument("H5Output: field '" + f.name + "' has no data");
    for (std::size_t j = 0; j < i; ++j) {
      if (fields[j].name == f.name)
        throw std::invalid_argument("H5Output: field '" + f.name + "' given twice");
    }
  }
}

}  // namespace

int H5Output::write_frame(double time, const double* x, const std::vector<NodeField>& fields) {
  Impl& m = *impl_;
  m.require_open();
  if (!m.has_mesh) throw std::logic_error("H5Output: " + m.path + ": write_frame() before write_mesh()");
  if (x == nullptr) throw std::invalid_argument("H5Output: write_frame() needs positions");
  check_fields(fields);
  const int index = m.n_frames;
  const std::string group_name = frame_group_name(index);
  Hid group = m.make(H5Gcreate2(m.file.get(), group_name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                     H5Gclose, "cannot create group " + group_name);
  std::string attributes;
  try {
    m.write_double_attribute(group.get(), "time", time, group_name);
    const hsize_t dims[2] = {static_cast<hsize_t>(m.n_nodes), 3};
    m.write_dataset(group.get(), "x", group_name + "/x", 2, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, x);
    for (const NodeField& f : fields) {
      const std::string full = group_name + "/" + f.name;
      m.write_dataset(group.get(), f.name, full, f.components == 3 ? 2 : 1, dims, H5T_IEEE_F64LE,
                      H5T_NATIVE_DOUBLE, f.data);
      attributes += m.attribute_xml(f.name, full, f.components, false);
    }
  } catch (...) {
    group.reset();
    H5Ldelete(m.file.get(), group_name.c_str(), H5P_DEFAULT);  // drop the partial frame; best effort
    throw;
  }
  group.reset();
  const std::string time_text = format_double(time);
  m.frames_xml += m.grid_xml("frame_" + group_name.substr(8), group_name + "/x", &time_text, attributes);
  m.n_frames = index + 1;
  m.checked(H5Fflush(m.file.get(), H5F_SCOPE_LOCAL), "cannot flush file");
  m.write_xdmf();
  return index;
}

namespace {

// Index of `name` in `row`, or -1.
int find_column(const std::vector<std::pair<std::string, double>>& row, const std::string& name) {
  for (std::size_t i = 0; i < row.size(); ++i) {
    if (row[i].first == name) return static_cast<int>(i);
  }
  return -1;
}

std::string join_names(const std::vector<std::pair<std::string, double>>& row) {
  std::string s;
  for (const auto& c : row) s += (s.empty() ? "" : ", ") + c.first;
  return s;
}

}  // namespace

void H5Output::append_series(const std::vector<std::pair<std::string, double>>& row) {
  Impl& m = *impl_;
  m.require_open();
  if (row.empty()) throw std::invalid_argument("H5Output: append_series() with an empty row");
  for (std::size_t i = 0; i < row.size(); ++i) {
    check_name(row[i].first, "series column");
    if (find_column(row, row[i].first) != static_cast<int>(i)) {
      throw std::invalid_argument("H5Output: series column '" + row[i].first + "' given twice");
    }
  }
  if (m.series_columns.empty()) {
    m.create_series(row);
  } else {
    bool same = row.size() == m.series_columns.size();
    for (std::size_t i = 0; same && i < m.series_columns.size(); ++i) {
      same = find_column(row, m.series_columns[i]) >= 0;
    }
    if (!same) {
      std::vector<std::pair<std::string, double>> first;
      for (const auto& c : m.series_columns) first.emplace_back(c, 0.0);
      throw std::invalid_argument("H5Output: series columns changed from {" + join_names(first) + "} to {" +
                                  join_names(row) + "}");
    }
  }
  for (std::size_t i = 0; i < m.series_columns.size(); ++i) {
    const double value = row[static_cast<std::size_t>(find_column(row, m.series_columns[i]))].second;
    m.append_value(m.series_sets[i].get(), m.series_columns[i], value);
  }
  ++m.series_rows;
}

void H5Output::flush() {
  impl_->require_open();
  impl_->checked(H5Fflush(impl_->file.get(), H5F_SCOPE_LOCAL), "cannot flush file");
  if (impl_->has_mesh) impl_->write_xdmf();
}

void H5Output::close() {
  Impl& m = *impl_;
  if (m.closed) return;
  m.closed = true;
  // Release every handle even if the XDMF cannot be written, then report the first failure.
  std::string xdmf_error;
  try {
    if (m.has_mesh) m.write_xdmf();
  } catch (const IoError& e) {
    xdmf_error = e.what();
  }
  m.series_sets.clear();
  const herr_t status = m.file.reset();
  if (status < 0) m.fail("cannot close file (disk full?)");
  if (!xdmf_error.empty()) throw IoError(xdmf_error);
}

}  // namespace dcm
