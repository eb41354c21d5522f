#include "cli.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <stdexcept>

#include "camproj/file_io.h"
#include "camproj/terminal_text.h"

namespace camproj::cli {

namespace {

bool ParseDouble(const std::string& text, double* value) {
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto [ptr, error] = std::from_chars(begin, end, *value);
  return error == std::errc() && ptr == end && std::isfinite(*value);
}

// A validator of finite numbers `accepted` accepts; `requirement` words what it does not
// ("positive"), `description` is the help's type suffix ("POSITIVE", or "" for none).
CLI::Validator FiniteValidator(const std::function<bool(double)>& accepted,
                               const std::string& requirement, const std::string& description) {
  return CLI::Validator(
      [accepted, requirement](std::string& text) -> std::string {
        double value = 0.0;
        if (!ParseDouble(text, &value)) return "\"" + text + "\" is not a finite number";
        if (!accepted(value)) return "must be " + requirement + ", got " + text;
        return "";
      },
      description);
}

}  // namespace

const CLI::Validator& FiniteNumber() {
  static const CLI::Validator validator = FiniteValidator([](double) { return true; }, "", "");
  return validator;
}

const CLI::Validator& PositiveFinite() {
  static const CLI::Validator validator =
      FiniteValidator([](double v) { return v > 0.0; }, "positive", "POSITIVE");
  return validator;
}

const CLI::Validator& NonNegativeFinite() {
  static const CLI::Validator validator =
      FiniteValidator([](double v) { return v >= 0.0; }, "0 or more", "NONNEGATIVE");
  return validator;
}

ImageSize ParseImageSize(const std::string& text, const std::string& option) {
  const size_t x = text.find('x');
  int width = 0;
  int height = 0;
  if (x != std::string::npos) {
    const auto [w_end, w_error] = std::from_chars(text.data(), text.data() + x, width);
    const auto [h_end, h_error] = std::from_chars(text.data() + x + 1, text.data() + text.size(), height);
    if (w_error == std::errc() && h_error == std::errc() && w_end == text.data() + x &&
        h_end == text.data() + text.size() && width > 0 && height > 0) {
      if (width > kMaxImageSide || height > kMaxImageSide) {
        throw UsageError(option + ": at most " + std::to_string(kMaxImageSide) +
                         " px per side, got \"" + text + "\"");
      }
      return {width, height};
    }
  }
  throw UsageError(option + ": expected WIDTHxHEIGHT in pixels (e.g. 1920x1080), got \"" + text + "\"");
}

std::vector<double> ParseNumbers(const std::string& text, size_t count, const std::string& option) {
  std::vector<double> numbers;
  size_t begin = 0;
  while (begin <= text.size()) {
    size_t end = text.find(',', begin);
    if (end == std::string::npos) end = text.size();
    double value = 0.0;
    if (!ParseDouble(text.substr(begin, end - begin), &value)) {
      throw UsageError(option + ": \"" + text.substr(begin, end - begin) +
                       "\" is not a finite number (in \"" + text + "\")");
    }
    numbers.push_back(value);
    begin = end + 1;
  }
  if (numbers.size() != count) {
    throw UsageError(option + ": expected " + std::to_string(count) +
                     " comma-separated numbers, got " + std::to_string(numbers.size()) + " in \"" +
                     text + "\"");
  }
  return numbers;
}

PixelOrigin PixelOriginOfOption(const CLI::Option* option, const std::string& value,
                                PixelOrigin camera_file_origin, const std::string& camera_path,
                                const std::string& pixels) {
  const PixelOrigin origin = PixelOriginFromString(value);
  if (option->count() == 0 && camera_file_origin != origin) {
    std::cerr << "camproj: note: " << TerminalSafe(camera_path) << " states its cx, cy in the "
              << ToString(camera_file_origin) << " convention (its pixel_origin), but "
              << TerminalSafe(pixels) << " in the " << ToString(origin)
              << " convention (--pixel-origin's default; the two differ by 0.5 px along u and "
              << "v): give --pixel-origin " << ToString(camera_file_origin) << " to use the "
              << "camera file's\n";
  }
  return origin;
}

void RequireDistinctOptionOutputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  try {
    RequireDistinctOutputs(outputs);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

std::vector<std::string> ExpandInputs(const std::vector<std::string>& paths) {
  std::vector<std::string> inputs;
  for (const std::string& path : paths) {
    if (!std::filesystem::is_directory(path)) {
      inputs.push_back(path);
      continue;
    }
    std::vector<std::string> found;
    for (const auto& entry : std::filesystem::directory_iterator(path)) {
      if (entry.is_regular_file() && entry.path().extension() == ".csv") {
        found.push_back(entry.path().string());
      }
    }
    if (found.empty()) throw UsageError(path + ": a folder without *.csv files");
    std::sort(found.begin(), found.end());
    inputs.insert(inputs.end(), found.begin(), found.end());
  }
  return inputs;
}

}  // namespace camproj::cli
