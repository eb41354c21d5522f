#include "view/obj_mesh.h"

#include <charconv>
#include <cmath>
#include <string_view>

#include "camproj/errors.h"
#include "check.h"

namespace camproj::internal {

namespace {

std::vector<std::string_view> Fields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

}  // namespace

ObjMesh ParseObjMesh(const std::string& text, const std::string& source) {
  ObjMesh mesh;
  size_t vertices = 0;
  size_t line_number = 0;
  size_t begin = 0;
  while (begin < text.size()) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + begin, end - begin);
    begin = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::vector<std::string_view> fields = Fields(line);
    if (fields.empty()) continue;
    const auto fail = [&](const std::string& what) {
      throw InputError(Concat(source, ": line ", line_number, ": ", what));
    };
    if (fields[0] == "v") {
      if (fields.size() < 4) fail("a vertex needs x y z");
      if (++vertices > kMaxObjElements) fail(Concat("more than ", kMaxObjElements, " vertices"));
      for (int k = 1; k <= 3; ++k) {
        double value = 0.0;
        const std::string_view f = fields[k];
        const auto [ptr, error] = std::from_chars(f.data(), f.data() + f.size(), value);
        if (error != std::errc() || ptr != f.data() + f.size() || !std::isfinite(value)) {
          fail(Concat("vertex coordinate ", k, " is not a finite number: \"",
                      std::string(f.substr(0, 40)), "\""));
        }
        mesh.positions.push_back(value);
      }
    } else if (fields[0] == "f") {
      if (fields.size() < 4) fail("a face needs at least 3 vertices");
      std::vector<uint32_t> face;
      for (size_t k = 1; k < fields.size(); ++k) {
        const std::string_view f = fields[k].substr(0, fields[k].find('/'));
        long long index = 0;
        const auto [ptr, error] = std::from_chars(f.data(), f.data() + f.size(), index);
        if (error != std::errc() || ptr != f.data() + f.size() || index == 0) {
          fail(Concat("face vertex ", k, " is not a vertex index: \"",
                      std::string(fields[k].substr(0, 40)), "\""));
        }
        const long long resolved = index > 0 ? index - 1 : static_cast<long long>(vertices) + index;
        if (resolved < 0 || resolved >= static_cast<long long>(vertices)) {
          fail(Concat("face vertex ", k, " refers to vertex ", index, " but ", vertices,
                      " are defined so far"));
        }
        face.push_back(static_cast<uint32_t>(resolved));
      }
      for (size_t k = 1; k + 1 < face.size(); ++k) {
        if (mesh.triangles.size() / 3 >= kMaxObjElements) {
          fail(Concat("more than ", kMaxObjElements, " triangles"));
        }
        mesh.triangles.insert(mesh.triangles.end(), {face[0], face[k], face[k + 1]});
      }
    }
  }
  return mesh;
}

}  // namespace camproj::internal
