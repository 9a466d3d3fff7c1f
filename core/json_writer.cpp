#include "core/json_writer.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "core/errors.hpp"

namespace dcm {

std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

JsonObject& JsonObject::add(const std::string& key, double value) {
  members_.emplace_back(key, json_number(value));
  return *this;
}
JsonObject& JsonObject::add(const std::string& key, long long value) {
  members_.emplace_back(key, std::to_string(value));
  return *this;
}
JsonObject& JsonObject::add(const std::string& key, bool value) {
  members_.emplace_back(key, value ? "true" : "false");
  return *this;
}
JsonObject& JsonObject::add(const std::string& key, const std::string& value) {
  members_.emplace_back(key, json_string(value));
  return *this;
}
JsonObject& JsonObject::add(const std::string& key, const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + json_number(values[i]);
  members_.emplace_back(key, text + "]");
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, const std::vector<std::vector<double>>& rows) {
  std::string text = "[";
  for (std::size_t r = 0; r < rows.size(); ++r) {
    text += r ? ", [" : "[";
    for (std::size_t i = 0; i < rows[r].size(); ++i) text += (i ? ", " : "") + json_number(rows[r][i]);
    text += "]";
  }
  members_.emplace_back(key, text + "]");
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, const std::vector<std::string>& texts) {
  std::string text = "[";
  for (std::size_t i = 0; i < texts.size(); ++i) text += (i ? ", " : "") + json_string(texts[i]);
  members_.emplace_back(key, text + "]");
  return *this;
}

std::string JsonObject::str() const {
  std::string out = "{\n";
  for (std::size_t i = 0; i < members_.size(); ++i)
    out += "  " + json_string(members_[i].first) + ": " + members_[i].second +
           (i + 1 < members_.size() ? ",\n" : "\n");
  return out + "}\n";
}

void JsonObject::write(const std::string& path) const {
  // An I/O failure (a full disk, a folder where the file goes) is the user's to fix: IoError, exit 2, and the
  // temporary file removed (session 41: geometry left geometry.json.tmp and called it an internal error).
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    f << str();
    f.close();
    if (!f) {
      std::remove(tmp.c_str());
      throw IoError(path + ": cannot write the file (" + tmp + " could not be written)");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw IoError(path + ": cannot write the file (" + std::strerror(err) + ")");
  }
}

}  // namespace dcm
