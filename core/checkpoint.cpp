// Checkpoint files (HDF5): atomic write (temporary file + rename) and read. Layout in core/checkpoint.hpp.
#include "core/checkpoint.hpp"

#include <hdf5.h>

#include <cstdio>
#include <filesystem>

#include "core/h5_links.hpp"

namespace dcm {
namespace {

const char* const kFormat =
    "dcm-checkpoint-3";  // 2: icosphere nodes numbered for locality (session 22); 3: in bands (session 24)

// Closes an HDF5 identifier on scope exit.
struct Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~Handle() {
    if (id >= 0) close(id);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
};

hid_t string_type() {
  const hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, H5T_VARIABLE);
  H5Tset_cset(t, H5T_CSET_UTF8);
  return t;
}

bool write_string(hid_t loc, const char* name, const std::string& text, bool attribute) {
  Handle type(string_type(), H5Tclose);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  const char* ptr = text.c_str();
  if (attribute) {
    Handle a(H5Acreate2(loc, name, type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    return a.id >= 0 && H5Awrite(a.id, type.id, &ptr) >= 0;
  }
  Handle d(H5Dcreate2(loc, name, type.id, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  return d.id >= 0 && H5Dwrite(d.id, type.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, &ptr) >= 0;
}

bool read_string(hid_t obj, bool attribute, std::string& out) {
  Handle type(string_type(), H5Tclose);
  char* ptr = nullptr;
  const herr_t status =
      attribute ? H5Aread(obj, type.id, &ptr) : H5Dread(obj, type.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, &ptr);
  if (status < 0 || ptr == nullptr) return false;
  out = ptr;
  H5free_memory(ptr);
  return true;
}

bool is_hdf5(const std::string& path) {
#if H5_VERSION_GE(1, 12, 0)
  return H5Fis_accessible(path.c_str(), H5P_DEFAULT) > 0;
#else
  return H5Fis_hdf5(path.c_str()) > 0;
#endif
}

bool write_all(hid_t file, const Checkpoint& c) {
  if (!write_string(file, "format", kFormat, true)) return false;
  Handle arrays(H5Gcreate2(file, "arrays", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  Handle texts(H5Gcreate2(file, "texts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (arrays.id < 0 || texts.id < 0) return false;
  for (const auto& [name, values] : c.arrays) {
    const hsize_t dims[1] = {values.size()};
    Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose);
    Handle d(
        H5Dcreate2(arrays.id, name.c_str(), H5T_IEEE_F64LE, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        H5Dclose);
    if (d.id < 0) return false;
    if (!values.empty() &&
        H5Dwrite(d.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
      return false;
  }
  for (const auto& [name, text] : c.texts) {
    if (!write_string(texts.id, name.c_str(), text, false)) return false;
  }
  return true;
}

}  // namespace

void write_checkpoint(const std::string& path, const Checkpoint& checkpoint) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const std::string tmp = path + ".tmp";
  bool ok = false;
  {
    const hid_t file = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) throw IoError(tmp + ": cannot create the checkpoint file (folder missing or not writable)");
    ok = write_all(file, checkpoint);
    ok = H5Fclose(file) >= 0 && ok;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    throw IoError(tmp + ": cannot write the checkpoint (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw IoError(path + ": cannot replace the checkpoint (" + ec.message() + ")");
  }
}

Checkpoint read_checkpoint(const std::string& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw IoError(path + ": no such checkpoint file");
  if (!is_hdf5(path)) throw IoError(path + ": not an HDF5 file (a dcm checkpoint is <out>/checkpoint.h5)");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file.id < 0) throw IoError(path + ": cannot open the checkpoint file");
  const auto not_a_checkpoint = [&] { return IoError(path + ": not a dcm checkpoint file"); };
  std::string format;
  {
    if (H5Aexists(file.id, "format") <= 0) throw not_a_checkpoint();
    Handle a(H5Aopen(file.id, "format", H5P_DEFAULT), H5Aclose);
    if (a.id < 0 || !read_string(a.id, true, format)) throw not_a_checkpoint();
  }
  if (format != kFormat)
    throw IoError(path + ": checkpoint format '" + format + "' is not the one this dcm reads ('" + kFormat +
                  "')");
  Checkpoint c;
  c.origin = path;
  Handle arrays(H5Gopen2(file.id, "arrays", H5P_DEFAULT), H5Gclose);
  Handle texts(H5Gopen2(file.id, "texts", H5P_DEFAULT), H5Gclose);
  if (arrays.id < 0 || texts.id < 0) throw not_a_checkpoint();
  for (const std::string& name : detail::h5_link_names(arrays.id)) {
    Handle d(H5Dopen2(arrays.id, name.c_str(), H5P_DEFAULT), H5Dclose);
    Handle space(H5Dget_space(d.id), H5Sclose);
    if (d.id < 0 || space.id < 0 || H5Sget_simple_extent_ndims(space.id) != 1) throw not_a_checkpoint();
    hsize_t n = 0;
    H5Sget_simple_extent_dims(space.id, &n, nullptr);
    std::vector<double> values(n);
    if (n > 0 && H5Dread(d.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
      throw IoError(path + ": cannot read '" + name + "'");
    c.arrays[name] = std::move(values);
  }
  for (const std::string& name : detail::h5_link_names(texts.id)) {
    Handle d(H5Dopen2(texts.id, name.c_str(), H5P_DEFAULT), H5Dclose);
    std::string text;
    if (d.id < 0 || !read_string(d.id, false, text)) throw IoError(path + ": cannot read '" + name + "'");
    c.texts[name] = std::move(text);
  }
  return c;
}

}  // namespace dcm
