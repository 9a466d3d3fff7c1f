#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/checkpoint.hpp"
#include "core/h5_output.hpp"
#include "dcm_config.hpp"

namespace {

namespace fs = std::filesystem;
using dcm::Checkpoint;
using dcm::H5Output;
using dcm::IoError;
using dcm::NodeField;
using dcm::read_checkpoint;
using dcm::write_checkpoint;

#ifndef DCM_SOURCE_DIR
#define DCM_SOURCE_DIR "."
#endif

constexpr int k_nodes = 6, k_tris = 8;

// Octahedron with outward triangles; coordinates that are not exact binary fractions.
struct Octahedron {
  std::vector<double> x;
  std::vector<int> tris = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  std::vector<int> node_cell = {0, 0, 1, 1, 2, 2};
  Octahedron() {
    const double r = 1e-6 / 3.0;
    x = {r, 0, 0, -r, 0, 0, 0, r, 0, 0, -r, 0, 0, 0, r, 0, 0, -r};
  }
};

// Per-frame data: positions, a scalar and a vector field, all distinct per frame.
struct FrameData {
  double time;
  std::vector<double> x, pressure, force;
  explicit FrameData(int k) : time(0.1 * k + 1e-7 / 3.0) {
    const Octahedron o;
    for (int i = 0; i < k_nodes * 3; ++i) x.push_back(o.x[i] * (1.0 + 0.01 * k) + 1e-9 * i / 7.0);
    for (int i = 0; i < k_nodes; ++i) pressure.push_back(100.0 / 3.0 * (k + 1) + i * 0.1);
    for (int i = 0; i < k_nodes * 3; ++i) force.push_back(-1e-12 * (i + 1) / (k + 3.0));
  }
  std::vector<NodeField> fields() const {
    return {{"pressure", 1, pressure.data()}, {"force", 3, force.data()}};
  }
};

std::vector<std::pair<std::string, double>> series_row(int i) {
  return {{"time", i * 0.25 / 3.0}, {"energy", 1e-15 * (i + 1) / 7.0}, {"area", 12.5 + i}};
}

// --- reading back with the HDF5 C API ---

struct Handle {
  hid_t id;
  herr_t (*closer)(hid_t);
  ~Handle() {
    if (id >= 0) closer(id);
  }
};

bool exists(hid_t file, const std::string& path) { return H5Lexists(file, path.c_str(), H5P_DEFAULT) > 0; }

std::vector<hsize_t> dims_of(hid_t file, const std::string& path) {
  Handle set{H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose};
  if (set.id < 0) return {};
  Handle space{H5Dget_space(set.id), H5Sclose};
  std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space.id)));
  H5Sget_simple_extent_dims(space.id, dims.data(), nullptr);
  return dims;
}

template <typename T>
std::vector<T> read_all(hid_t file, const std::string& path, hid_t mem_type) {
  std::size_t n = 1;
  for (hsize_t d : dims_of(file, path)) n *= d;
  std::vector<T> out(n);
  Handle set{H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose};
  EXPECT_GE(set.id, 0) << path;
  EXPECT_GE(H5Dread(set.id, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << path;
  return out;
}

std::vector<double> read_doubles(hid_t f, const std::string& p) {
  return read_all<double>(f, p, H5T_NATIVE_DOUBLE);
}
std::vector<int> read_ints(hid_t f, const std::string& p) { return read_all<int>(f, p, H5T_NATIVE_INT); }

H5T_class_t stored_class(hid_t file, const std::string& path, std::size_t* size) {
  Handle set{H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose};
  Handle type{H5Dget_type(set.id), H5Tclose};
  *size = H5Tget_size(type.id);
  return H5Tget_class(type.id);
}

double read_time(hid_t file, const std::string& group) {
  Handle g{H5Gopen2(file, group.c_str(), H5P_DEFAULT), H5Gclose};
  Handle a{H5Aopen(g.id, "time", H5P_DEFAULT), H5Aclose};
  double t = -1;
  EXPECT_GE(H5Aread(a.id, H5T_NATIVE_DOUBLE, &t), 0) << group;
  return t;
}

// Reads a root string attribute, variable or fixed length.
std::string read_text(hid_t file, const std::string& name) {
  Handle a{H5Aopen(file, name.c_str(), H5P_DEFAULT), H5Aclose};
  if (a.id < 0) return "<missing>";
  Handle type{H5Aget_type(a.id), H5Tclose};
  EXPECT_EQ(H5Tget_class(type.id), H5T_STRING);
  EXPECT_EQ(H5Tget_cset(type.id), H5T_CSET_UTF8);
  if (H5Tis_variable_str(type.id) > 0) {
    char* p = nullptr;
    EXPECT_GE(H5Aread(a.id, type.id, &p), 0);
    std::string s = p != nullptr ? p : "";
    H5free_memory(p);
    return s;
  }
  std::string s(H5Tget_size(type.id), '\0');
  EXPECT_GE(H5Aread(a.id, type.id, &s[0]), 0);
  return s.substr(0, s.find('\0'));
}

bool same_bits(const std::vector<double>& a, const double* b, std::size_t n) {
  return a.size() == n && std::memcmp(a.data(), b, n * sizeof(double)) == 0;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int count_of(const std::string& text, const std::string& needle) {
  int n = 0;
  for (auto p = text.find(needle); p != std::string::npos; p = text.find(needle, p + 1)) ++n;
  return n;
}

// Every piece of `text` between an `open` marker and the next `close` marker.
std::vector<std::string> all_between(const std::string& text, const std::string& open,
                                     const std::string& close) {
  std::vector<std::string> out;
  for (auto p = text.find(open); p != std::string::npos; p = text.find(open, p + 1)) {
    const auto begin = p + open.size(), end = text.find(close, begin);
    if (end == std::string::npos) break;
    out.push_back(text.substr(begin, end - begin));
  }
  return out;
}

// Every HDF reference in the XDMF must name `h5_name`, exist, and have the declared dimensions.
void expect_references_valid(const std::string& xmf, hid_t file, const std::string& h5_name) {
  const std::vector<std::string> items = all_between(xmf, "Dimensions=\"", "</DataItem>");
  EXPECT_GT(items.size(), 0u);
  for (const std::string& item : items) {  // e.g. 6 3">run.h5:/mesh/x
    const auto quote = item.find("\">"), colon = item.find(':');
    ASSERT_NE(quote, std::string::npos) << item;
    ASSERT_NE(colon, std::string::npos) << item;
    const std::string dims_text = item.substr(0, quote), path = item.substr(colon + 1);
    EXPECT_EQ(item.substr(quote + 2, colon - quote - 2), h5_name);
    ASSERT_TRUE(exists(file, path)) << path;
    std::string actual;
    for (hsize_t d : dims_of(file, path)) actual += (actual.empty() ? "" : " ") + std::to_string(d);
    EXPECT_EQ(actual, dims_text) << path;
  }
}

bool system_python_has_h5py() {
  return std::system("/usr/bin/python3 -c 'import h5py, numpy' >/dev/null 2>&1") == 0;
}

int run_checker(const std::string& xmf, const std::string& log) {
  const std::string cmd =
      "/usr/bin/python3 '" DCM_SOURCE_DIR "/scripts/check_xdmf.py' '" + xmf + "' >'" + log + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class H5OutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "dcm_h5_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(&tmpl[0]), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

  // Mesh, 3 frames, 5 series rows, text and a scalar.
  void write_run(H5Output& out) const {
    const Octahedron o;
    out.write_text("scene", scene_text_);
    out.write_scalar("dt", 1e-3 / 3.0);
    out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data());
    for (int k = 0; k < 3; ++k) {
      const FrameData f(k);
      EXPECT_EQ(out.write_frame(f.time, f.x.data(), f.fields()), k);
    }
    for (int i = 0; i < 5; ++i) out.append_series(series_row(i));
  }

  std::string dir_;
  const std::string scene_text_ = "[mesh]\nradius_m = 3.25e-6  # \xc2\xb5m \"quoted\" <tag>\n";
};

TEST_F(H5OutputTest, RoundTripsMeshFramesSeriesAndText) {
  {
    H5Output out(path("run.h5"));
    EXPECT_EQ(out.xdmf_path(), path("run.xmf"));
    write_run(out);
    out.close();
  }
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  const Octahedron o;
  using Dims = std::vector<hsize_t>;
  EXPECT_EQ(dims_of(file.id, "/mesh/x"), (Dims{6, 3}));
  EXPECT_EQ(dims_of(file.id, "/mesh/triangles"), (Dims{8, 3}));
  EXPECT_EQ(dims_of(file.id, "/mesh/node_cell"), (Dims{6}));
  EXPECT_TRUE(same_bits(read_doubles(file.id, "/mesh/x"), o.x.data(), o.x.size()));
  EXPECT_EQ(read_ints(file.id, "/mesh/triangles"), o.tris);
  EXPECT_EQ(read_ints(file.id, "/mesh/node_cell"), o.node_cell);
  std::size_t size = 0;
  EXPECT_EQ(stored_class(file.id, "/mesh/triangles", &size), H5T_INTEGER);
  EXPECT_EQ(size, 4u);
  EXPECT_EQ(stored_class(file.id, "/mesh/x", &size), H5T_FLOAT);
  EXPECT_EQ(size, 8u);

  for (int k = 0; k < 3; ++k) {
    const FrameData f(k);
    char group[32];
    std::snprintf(group, sizeof group, "/frames/%06d", k);
    const std::string g = group;
    EXPECT_EQ(read_time(file.id, g), f.time);
    EXPECT_EQ(dims_of(file.id, g + "/x"), (Dims{6, 3}));
    EXPECT_EQ(dims_of(file.id, g + "/pressure"), (Dims{6}));
    EXPECT_EQ(dims_of(file.id, g + "/force"), (Dims{6, 3}));
    EXPECT_TRUE(same_bits(read_doubles(file.id, g + "/x"), f.x.data(), f.x.size())) << g;
    EXPECT_TRUE(same_bits(read_doubles(file.id, g + "/pressure"), f.pressure.data(), f.pressure.size())) << g;
    EXPECT_TRUE(same_bits(read_doubles(file.id, g + "/force"), f.force.data(), f.force.size())) << g;
  }
  EXPECT_FALSE(exists(file.id, "/frames/000003"));

  for (const char* column : {"time", "energy", "area"}) {
    const std::string p = std::string("/series/") + column;
    ASSERT_EQ(dims_of(file.id, p), (Dims{5})) << p;
    const std::vector<double> values = read_doubles(file.id, p);
    for (int i = 0; i < 5; ++i) {
      for (const auto& [name, v] : series_row(i)) {
        if (name == column) {
          EXPECT_TRUE(same_bits({values[static_cast<std::size_t>(i)]}, &v, 1)) << p << i;
        }
      }
    }
  }
  EXPECT_EQ(read_text(file.id, "scene"), scene_text_);
  EXPECT_FALSE(read_text(file.id, "dcm_version").empty());
  const double dt = 1e-3 / 3.0;
  EXPECT_TRUE(same_bits(read_doubles(file.id, "/meta/dt"), &dt, 1));
  EXPECT_EQ(dims_of(file.id, "/meta/dt"), Dims{});
}

TEST_F(H5OutputTest, SeriesDatasetsAreExtendibleAndChunked) {
  {
    H5Output out(path("run.h5"));
    for (int i = 0; i < 2500; ++i) out.append_series({{"step", double(i)}});
    out.close();
  }
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  Handle set{H5Dopen2(file.id, "/series/step", H5P_DEFAULT), H5Dclose};
  Handle space{H5Dget_space(set.id), H5Sclose};
  hsize_t dims[1] = {0}, max_dims[1] = {0};
  ASSERT_EQ(H5Sget_simple_extent_dims(space.id, dims, max_dims), 1);
  EXPECT_EQ(dims[0], 2500u);
  EXPECT_EQ(max_dims[0], H5S_UNLIMITED);
  Handle props{H5Dget_create_plist(set.id), H5Pclose};
  EXPECT_EQ(H5Pget_layout(props.id), H5D_CHUNKED);
  const std::vector<double> v = read_doubles(file.id, "/series/step");
  for (int i = 0; i < 2500; ++i) ASSERT_EQ(v[static_cast<std::size_t>(i)], double(i));
}

TEST_F(H5OutputTest, SeriesAcceptsReorderedColumnsAndRejectsChangedOnes) {
  H5Output out(path("run.h5"));
  out.append_series(series_row(0));
  auto reordered = series_row(1);
  std::swap(reordered[0], reordered[2]);
  EXPECT_NO_THROW(out.append_series(reordered));
  auto renamed = series_row(2);
  renamed[1].first = "energy_J";
  EXPECT_THROW(out.append_series(renamed), std::invalid_argument);
  auto extra = series_row(2);
  extra.emplace_back("volume", 1.0);
  EXPECT_THROW(out.append_series(extra), std::invalid_argument);
  auto fewer = series_row(2);
  fewer.pop_back();
  EXPECT_THROW(out.append_series(fewer), std::invalid_argument);
  EXPECT_THROW(out.append_series({{"a", 1}, {"a", 2}}), std::invalid_argument);
  EXPECT_THROW(out.append_series({}), std::invalid_argument);
  out.close();
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  EXPECT_EQ(dims_of(file.id, "/series/area"), std::vector<hsize_t>{2});
  EXPECT_EQ(read_doubles(file.id, "/series/area")[1], series_row(1)[2].second);
}

TEST_F(H5OutputTest, XdmfDescribesEveryFrame) {
  {
    H5Output out(path("run.h5"));
    write_run(out);
  }
  const std::string xmf = slurp(path("run.xmf"));
  EXPECT_NE(xmf.find("<Xdmf Version=\"3.0\">"), std::string::npos);
  EXPECT_NE(xmf.find("GridType=\"Collection\" CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_EQ(count_of(xmf, "<Grid Name="), 4);  // the collection and 3 frames
  EXPECT_EQ(count_of(xmf, "<Time Value="), 3);
  EXPECT_EQ(count_of(xmf, "TopologyType=\"Triangle\" NumberOfElements=\"8\""), 3);
  EXPECT_EQ(count_of(xmf, "Dimensions=\"8 3\">run.h5:/mesh/triangles<"), 3);
  EXPECT_EQ(count_of(xmf, "Dimensions=\"6\">run.h5:/mesh/node_cell<"), 3);
  EXPECT_EQ(count_of(xmf, "Dimensions=\"6 3\">run.h5:/frames/000002/x<"), 1);
  EXPECT_EQ(count_of(xmf, "Dimensions=\"6\">run.h5:/frames/000001/pressure<"), 1);
  EXPECT_EQ(count_of(xmf, "Dimensions=\"6 3\">run.h5:/frames/000000/force<"), 1);
  EXPECT_EQ(count_of(xmf, "AttributeType=\"Vector\""), 3);
  EXPECT_EQ(count_of(xmf, "AttributeType=\"Scalar\""), 6);
  // Times round-trip exactly through %.17g.
  const std::vector<std::string> times = all_between(xmf, "<Time Value=\"", "\"/>");
  ASSERT_EQ(times.size(), 3u);
  for (int k = 0; k < 3; ++k)
    EXPECT_EQ(std::strtod(times[std::size_t(k)].c_str(), nullptr), FrameData(k).time);
  EXPECT_FALSE(fs::exists(path("run.xmf.tmp")));
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  expect_references_valid(xmf, file.id, "run.h5");
}

TEST_F(H5OutputTest, XdmfWithoutFramesIsOneStaticGrid) {
  {
    H5Output out(path("mesh_only.h5"));
    const Octahedron o;
    out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data());
  }
  const std::string xmf = slurp(path("mesh_only.xmf"));
  EXPECT_EQ(count_of(xmf, "<Grid Name="), 1);
  EXPECT_EQ(count_of(xmf, "Collection"), 0);
  EXPECT_EQ(count_of(xmf, "Dimensions=\"6 3\">mesh_only.h5:/mesh/x<"), 1);
  EXPECT_EQ(count_of(xmf, "<Attribute Name=\"node_cell\" AttributeType=\"Scalar\""), 1);
  Handle file{H5Fopen(path("mesh_only.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  expect_references_valid(xmf, file.id, "mesh_only.h5");
}

TEST_F(H5OutputTest, XdmfIsRewrittenAfterEachFrame) {
  H5Output out(path("run.h5"));
  const Octahedron o;
  out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data());
  for (int k = 0; k < 3; ++k) {
    const FrameData f(k);
    out.write_frame(f.time, f.x.data(), f.fields());
    EXPECT_EQ(count_of(slurp(out.xdmf_path()), "<Time Value="), k + 1);
  }
}

TEST_F(H5OutputTest, UnwritablePathThrowsOneLineIoError) {
  for (const std::string& bad : {path("no/such/folder/run.h5"), dir_}) {
    try {
      H5Output out(bad);
      FAIL() << "no exception for " << bad;
    } catch (const dcm::IoError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(bad), std::string::npos) << msg;
      EXPECT_NE(msg.find("cannot create file"), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

TEST_F(H5OutputTest, MisuseThrows) {
  H5Output out(path("run.h5"));
  const Octahedron o;
  const FrameData f(0);
  EXPECT_THROW(out.write_frame(f.time, f.x.data(), f.fields()), std::logic_error);
  out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data());
  EXPECT_THROW(out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data()),
               std::logic_error);
  for (int components : {0, 2, 4, 9}) {
    const std::vector<NodeField> fields = {{"bad", components, f.pressure.data()}};
    EXPECT_THROW(out.write_frame(f.time, f.x.data(), fields), std::invalid_argument) << components;
  }
  EXPECT_THROW(out.write_frame(f.time, f.x.data(), {{"a/b", 1, f.pressure.data()}}), std::invalid_argument);
  EXPECT_THROW(out.write_frame(f.time, f.x.data(), {{"x", 3, f.force.data()}}), std::invalid_argument);
  EXPECT_THROW(out.write_text("", "x"), std::invalid_argument);
  // A rejected frame leaves nothing behind: the next one is still frame 0.
  EXPECT_EQ(out.write_frame(f.time, f.x.data(), f.fields()), 0);
  out.close();
  EXPECT_NO_THROW(out.close());
  EXPECT_THROW(out.write_frame(f.time, f.x.data(), f.fields()), std::logic_error);
  EXPECT_THROW(out.append_series(series_row(0)), std::logic_error);
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);  // no handle leaked, error paths included
}

TEST_F(H5OutputTest, BadMeshThrowsInvalidArgument) {
  H5Output out(path("run.h5"));
  Octahedron o;
  o.tris[5] = k_nodes;
  EXPECT_THROW(out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data()),
               std::invalid_argument);
  EXPECT_THROW(out.write_mesh(o.x.data(), 0, o.tris.data(), 0, o.node_cell.data()), std::invalid_argument);
}

TEST_F(H5OutputTest, DestructorWithoutCloseLeavesValidFiles) {
  {
    H5Output out(path("run.h5"));
    write_run(out);
  }
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  const FrameData f(2);
  EXPECT_TRUE(same_bits(read_doubles(file.id, "/frames/000002/force"), f.force.data(), f.force.size()));
  EXPECT_EQ(dims_of(file.id, "/series/energy"), std::vector<hsize_t>{5});
  expect_references_valid(slurp(path("run.xmf")), file.id, "run.h5");
}

TEST_F(H5OutputTest, KilledRunLeavesReadableFiles) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the child must never return into the test runner
    try {
      H5Output out(path("run.h5"));
      const Octahedron o;
      out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data());
      for (int k = 0; k < 2; ++k) {
        const FrameData f(k);
        out.write_frame(f.time, f.x.data(), f.fields());
      }
      kill(getpid(), SIGKILL);
    } catch (...) {
    }
    _exit(2);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  const FrameData f(1);
  EXPECT_TRUE(same_bits(read_doubles(file.id, "/frames/000001/x"), f.x.data(), f.x.size()));
  EXPECT_EQ(read_time(file.id, "/frames/000001"), f.time);
  const std::string xmf = slurp(path("run.xmf"));
  EXPECT_EQ(count_of(xmf, "<Time Value="), 2);
  expect_references_valid(xmf, file.id, "run.h5");
}

TEST_F(H5OutputTest, TextAndScalarsCanBeLargeAndReplaced) {
  std::string big;
  for (int i = 0; big.size() < 200000; ++i) big += "line " + std::to_string(i) + " \xe2\x9c\x93\n";
  {
    H5Output out(path("run.h5"));
    out.write_text("scene", "first");
    out.write_text("scene", big);
    out.write_scalar("k", 1.0);
    out.write_scalar("k", 2.5);
    out.close();
  }
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  EXPECT_EQ(read_text(file.id, "scene"), big);
  EXPECT_EQ(read_doubles(file.id, "/meta/k"), std::vector<double>{2.5});
  EXPECT_FALSE(fs::exists(path("run.xmf")));  // no mesh, nothing for ParaView to show
}

TEST_F(H5OutputTest, PythonCheckerAcceptsOutputAndRejectsBrokenXdmf) {
  if (!system_python_has_h5py()) GTEST_SKIP() << "/usr/bin/python3 lacks h5py";
  {
    H5Output out(path("run.h5"));
    write_run(out);
  }
  EXPECT_EQ(run_checker(path("run.xmf"), path("log.txt")), 0) << slurp(path("log.txt"));
  EXPECT_EQ(slurp(path("log.txt")), "xdmf ok: 3 frames\n");
  {
    H5Output out(path("static.h5"));
    const Octahedron o;
    out.write_mesh(o.x.data(), k_nodes, o.tris.data(), k_tris, o.node_cell.data());
  }
  EXPECT_EQ(run_checker(path("static.xmf"), path("log.txt")), 0) << slurp(path("log.txt"));
  EXPECT_EQ(slurp(path("log.txt")), "xdmf ok: 0 frames\n");

  std::string broken = slurp(path("run.xmf"));
  broken.replace(broken.find("Dimensions=\"6 3\">run.h5:/frames/000001/x"), 16, "Dimensions=\"7 3\"");
  std::ofstream(path("broken.xmf")) << broken;
  EXPECT_EQ(run_checker(path("broken.xmf"), path("log.txt")), 1);
  const std::string log = slurp(path("log.txt"));
  EXPECT_NE(log.find("/frames/000001/x"), std::string::npos) << log;
  EXPECT_EQ(count_of(log, "\n"), 1) << log;
}

}  // namespace

TEST_F(H5OutputTest, ResumeKeepsTheFirstFramesAndRestartsTheSeries) {
  {
    H5Output out(path("run.h5"));
    write_run(out);  // 3 frames, 5 series rows
  }
  std::string xmf_before;
  {
    H5Output out(path("run.h5"), H5Output::Resume{2});
    EXPECT_EQ(out.frames(), 2);
    const FrameData f(7);
    EXPECT_EQ(out.write_frame(f.time, f.x.data(), f.fields()), 2);
    out.append_series(series_row(9));
    out.close();
  }
  Handle file{H5Fopen(path("run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(read_time(file.id, "/frames/000001"), FrameData(1).time);
  EXPECT_EQ(read_time(file.id, "/frames/000002"), FrameData(7).time);  // the new frame replaced the third
  EXPECT_FALSE(exists(file.id, "/frames/000003"));
  EXPECT_EQ(dims_of(file.id, "/series/time"), std::vector<hsize_t>{1});
  EXPECT_EQ(read_text(file.id, "scene"), scene_text_);
  if (system_python_has_h5py()) {
    EXPECT_EQ(run_checker(path("run.xmf"), path("check.log")), 0);
  }
}

TEST_F(H5OutputTest, ResumeOfAMissingOrForeignFileThrowsIoError) {
  EXPECT_THROW(H5Output(path("none.h5"), H5Output::Resume{0}), IoError);
  {
    H5Output out(path("run.h5"));
    write_run(out);
  }
  try {
    H5Output(path("run.h5"), H5Output::Resume{4});
    FAIL() << "a resume past the frames in the file must throw";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("3 frames"), std::string::npos) << e.what();
  }
}

TEST_F(H5OutputTest, CheckpointRoundTripsBitForBitAndIsReplacedAtomically) {
  Checkpoint c;
  c.put("a.scalar", 1.0 / 3.0);
  c.put("a.array", std::vector<double>{-0.0, 1e-300, 6.02e23, std::nextafter(1.0, 2.0)});
  c.put("a.empty", std::vector<double>{});
  c.put_text("scene", scene_text_);
  c.put_text("csv", "t_s,r_cc_m\n0.1,2e-6\n");
  write_checkpoint(path("cp.h5"), c);
  c.put("a.scalar", 2.0);
  write_checkpoint(path("cp.h5"), c);  // over the old one
  EXPECT_FALSE(fs::exists(path("cp.h5.tmp")));
  const Checkpoint r = read_checkpoint(path("cp.h5"));
  EXPECT_EQ(r.scalar("a.scalar"), 2.0);
  const std::vector<double>& a = r.array("a.array", 4);
  EXPECT_TRUE(same_bits(a, c.arrays.at("a.array").data(), 4));
  EXPECT_TRUE(std::signbit(a[0]));
  EXPECT_TRUE(r.array("a.empty").empty());
  EXPECT_EQ(r.text("scene"), scene_text_);
  EXPECT_EQ(r.text("csv"), c.texts.at("csv"));
  EXPECT_THROW(r.array("a.array", 5), IoError);  // a checkpoint of another mesh
  EXPECT_THROW(r.scalar("missing"), IoError);
}

TEST_F(H5OutputTest, ReadingAnythingButACheckpointThrowsOneLineIoError) {
  {
    std::ofstream(path("text.h5")) << "not hdf5\n";
    H5Output out(path("run.h5"));
    write_run(out);
  }
  for (const std::string name : {"missing.h5", "text.h5", "run.h5"}) {
    try {
      read_checkpoint(path(name));
      FAIL() << name;
    } catch (const IoError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}
