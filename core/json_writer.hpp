#pragma once
// A flat JSON object writer for summaries (numbers with 17 significant digits, so values round-trip).
#include <string>
#include <utility>
#include <vector>

namespace dcm {

class JsonObject {
 public:
  JsonObject& add(const std::string& key, double value);
  JsonObject& add(const std::string& key, long long value);
  JsonObject& add(const std::string& key, int value) { return add(key, static_cast<long long>(value)); }
  JsonObject& add(const std::string& key, bool value);
  JsonObject& add(const std::string& key, const std::string& value);
  JsonObject& add(const std::string& key, const char* value) { return add(key, std::string(value)); }
  JsonObject& add(const std::string& key, const std::vector<double>& values);
  JsonObject& add(const std::string& key, const std::vector<std::vector<double>>& rows);  // list of lists
  JsonObject& add(const std::string& key, const std::vector<std::string>& texts);         // list of strings
  std::string str() const;
  // Writes to path via a temporary file and rename(), so a reader never sees half a file.
  void write(const std::string& path) const;

 private:
  std::vector<std::pair<std::string, std::string>> members_;  // key -> JSON text
};

std::string json_number(double value);  // non-finite values become null
std::string json_string(const std::string& text);

}  // namespace dcm
