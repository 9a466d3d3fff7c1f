#pragma once
// Names of the links (groups, datasets) in an HDF5 group, in name order; for dcm_io's readers
// (core/h5_output.cpp resume, core/checkpoint.cpp). Works with the HDF5 1.10 and 1.12+ APIs.
#include <hdf5.h>

#include <string>
#include <vector>

namespace dcm::detail {

inline std::vector<std::string> h5_link_names(hid_t group) {
  std::vector<std::string> names;
  H5Literate(
      group, H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->emplace_back(name);
        return 0;
      },
      &names);
  return names;
}

}  // namespace dcm::detail
