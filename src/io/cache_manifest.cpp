#include "io/cache_manifest.h"

#include <nlohmann/json.hpp>

#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

std::string readManifest(const std::string& text, const std::string& format, const std::string& key,
                         const std::vector<std::string>& verify, std::vector<ManifestFile>& files) {
  files.clear();
  // Without exceptions: json's value() throws when a field has another type than asked.
  const nlohmann::json manifest = nlohmann::json::parse(text, nullptr, false);
  if (manifest.is_discarded()) return "its manifest is missing or unreadable";
  if (!manifest.is_object()) return "it has another format";
  const auto format_field = manifest.find("format");
  if (format_field == manifest.end() || !format_field->is_string() || *format_field != format) {
    return "it has another format";
  }
  const auto key_field = manifest.find("key");
  if (key_field == manifest.end() || !key_field->is_string() || *key_field != key) {
    const std::string named = key_field != manifest.end() && key_field->is_string()
                                  ? clippedText(key_field->get<std::string>())
                                  : "?";
    return "it belongs to another request (key " + named + ")";
  }
  const auto listed = manifest.find("files");
  if (listed == manifest.end() || !listed->is_object() || listed->empty()) return "its manifest lists no files";
  for (const std::string& name : verify) {
    if (!listed->contains(name)) return "its manifest does not list " + name;
  }
  for (const auto& [name, expected] : listed->items()) {
    if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos) {
      return "its manifest names a bad file '" + clippedText(name) + "'";
    }
    const auto bytes = expected.is_object() ? expected.find("bytes") : expected.end();
    if (!expected.is_object() || bytes == expected.end() || !bytes->is_number_unsigned()) {
      return "its manifest gives no size for " + clippedText(name);
    }
    const auto checksum = expected.find("checksum64");
    files.push_back(ManifestFile{name, bytes->get<std::uint64_t>(),
                                 checksum != expected.end() && checksum->is_string() ? checksum->get<std::string>() : ""});
  }
  return "";
}

}  // namespace maximal_workspace
