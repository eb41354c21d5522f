#include "view/ply_vertices.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "camproj/errors.h"

namespace camproj {
namespace internal {

namespace {

constexpr size_t kMaxPlyVertices = 50'000'000;

// The PLY scalar types and their sizes in bytes (both spellings of the specification).
const std::map<std::string, int>& ScalarSizes() {
  static const std::map<std::string, int> sizes = {
      {"char", 1},  {"uchar", 1},  {"int8", 1},    {"uint8", 1},  {"short", 2},  {"ushort", 2},
      {"int16", 2}, {"uint16", 2}, {"int", 4},     {"uint", 4},   {"int32", 4},  {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  return sizes;
}

struct Property {
  std::string name;
  std::string type;        // scalar type, or the list's item type
  std::string count_type;  // a list's count type; empty for a scalar
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

class Reader {
 public:
  Reader(const std::string& bytes, const std::string& source) : bytes_(bytes), source_(source) {}

  std::vector<Eigen::Vector3d> Read() {
    ReadHeader();
    std::vector<Eigen::Vector3d> positions;
    for (const Element& element : elements_) {
      if (element.name != "vertex") {
        for (size_t i = 0; i < element.count; ++i) ReadItem(element, nullptr);
        continue;
      }
      int axes[3] = {-1, -1, -1};
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const std::string& name = element.properties[p].name;
        if (name == "x" || name == "y" || name == "z") axes[name[0] - 'x'] = static_cast<int>(p);
      }
      for (int axis = 0; axis < 3; ++axis) {
        if (axes[axis] < 0 || !element.properties[axes[axis]].count_type.empty()) {
          Fail(std::string("the vertex element has no scalar property ") + char('x' + axis));
        }
      }
      if (element.count > kMaxPlyVertices) {
        Fail("more than " + std::to_string(kMaxPlyVertices) + " vertices");
      }
      positions.reserve(element.count);
      std::vector<double> values;
      for (size_t i = 0; i < element.count; ++i) {
        ReadItem(element, &values);
        const Eigen::Vector3d x(values[axes[0]], values[axes[1]], values[axes[2]]);
        if (!x.allFinite()) Fail("vertex " + std::to_string(i + 1) + " is not finite");
        positions.push_back(x);
      }
      return positions;
    }
    Fail("no vertex element");
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(source_ + ": PLY: " + what);
  }

  void ReadHeader() {
    std::istringstream header;
    const size_t end = bytes_.find("end_header");
    if (bytes_.compare(0, 3, "ply") != 0 || end == std::string::npos) {
      Fail("not a PLY file (it must start with \"ply\" and have an \"end_header\" line)");
    }
    const size_t newline = bytes_.find('\n', end);
    if (newline == std::string::npos) Fail("nothing after end_header");
    data_ = newline + 1;
    std::istringstream lines(bytes_.substr(0, end));
    std::string line;
    std::getline(lines, line);  // "ply"
    while (std::getline(lines, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream words(line);
      std::string keyword;
      words >> keyword;
      if (keyword == "format") {
        words >> format_;
        if (format_ != "ascii" && format_ != "binary_little_endian" &&
            format_ != "binary_big_endian") {
          Fail("unknown format \"" + format_ + "\"");
        }
      } else if (keyword == "element") {
        Element element;
        long long count = -1;
        words >> element.name >> count;
        if (element.name.empty() || count < 0) Fail("bad element line \"" + line + "\"");
        element.count = static_cast<size_t>(count);
        elements_.push_back(element);
      } else if (keyword == "property") {
        if (elements_.empty()) Fail("a property before any element");
        Property property;
        std::string type;
        words >> type;
        if (type == "list") {
          words >> property.count_type >> property.type;
          if (!ScalarSizes().count(property.count_type)) Fail("unknown type in \"" + line + "\"");
        } else {
          property.type = type;
        }
        words >> property.name;
        if (!ScalarSizes().count(property.type) || property.name.empty()) {
          Fail("bad property line \"" + line + "\"");
        }
        elements_.back().properties.push_back(property);
      } else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
        Fail("unknown header line \"" + line + "\"");
      }
    }
    if (format_.empty()) Fail("no format line");
  }

  // One item of `element`; its scalar values into *values (lists skipped) when given.
  void ReadItem(const Element& element, std::vector<double>* values) {
    if (values != nullptr) values->assign(element.properties.size(), 0.0);
    for (size_t p = 0; p < element.properties.size(); ++p) {
      const Property& property = element.properties[p];
      if (!property.count_type.empty()) {
        const double count = ReadScalar(property.count_type);
        if (!(count >= 0.0 && count <= 1e6)) Fail("a list length of " + std::to_string(count));
        for (int k = 0; k < static_cast<int>(count); ++k) ReadScalar(property.type);
      } else {
        const double value = ReadScalar(property.type);
        if (values != nullptr) (*values)[p] = value;
      }
    }
  }

  double ReadScalar(const std::string& type) {
    if (format_ == "ascii") {
      while (data_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[data_]))) {
        ++data_;
      }
      const size_t begin = data_;
      while (data_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[data_]))) {
        ++data_;
      }
      if (begin == data_) Fail("the data ends before the header's elements do");
      const std::string word = bytes_.substr(begin, data_ - begin);
      char* end = nullptr;
      const double value = std::strtod(word.c_str(), &end);
      if (end != word.c_str() + word.size()) Fail("\"" + word + "\" is not a number");
      return value;
    }
    const int size = ScalarSizes().at(type);
    if (data_ + size > bytes_.size()) Fail("the data ends before the header's elements do");
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + data_, size);
    data_ += size;
    if (format_ == "binary_big_endian") {
      for (int k = 0; k < size / 2; ++k) std::swap(raw[k], raw[size - 1 - k]);
    }
    // Little-endian machines only (x86-64, ARM64 as Debian runs them).
    const std::string& t = type;
    if (t == "char" || t == "int8") return static_cast<int8_t>(raw[0]);
    if (t == "uchar" || t == "uint8") return raw[0];
    auto as = [&](auto value) {
      std::memcpy(&value, raw, sizeof value);
      return static_cast<double>(value);
    };
    if (t == "short" || t == "int16") return as(int16_t{});
    if (t == "ushort" || t == "uint16") return as(uint16_t{});
    if (t == "int" || t == "int32") return as(int32_t{});
    if (t == "uint" || t == "uint32") return as(uint32_t{});
    if (t == "float" || t == "float32") return as(float{});
    return as(double{});
  }

  const std::string& bytes_;
  const std::string& source_;
  std::string format_;
  std::vector<Element> elements_;
  size_t data_ = 0;
};

}  // namespace

std::vector<Eigen::Vector3d> PlyVertexPositions(const std::string& bytes,
                                                const std::string& source) {
  return Reader(bytes, source).Read();
}

}  // namespace internal
}  // namespace camproj
