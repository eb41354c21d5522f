// libFuzzer target for the fitter and the exporters on well-formed but adversarial scenes: what
// `camproj fit POINTS.csv --image-size WxH -o cam.json` and then `camproj export cam.json --to F`
// run, on scenes the input bytes build.
//
// A scene: 4-24 points and pixels, every number finite, the image 16-4000 px a side. Either a
// pinhole camera's view (field of view 2-170 degrees, lens shift, distance, direction, pixel
// noise, some pixels replaced: mis-clicks) or arbitrary pixels. The points sit on a grid of 1/8
// in [-1, 1]^3, so repeated points, lines, planes and slabs are common; then the world is scaled
// by 2^k (k in [-200, 200]) and moved by up to 2^60 scene sizes.
//
// The contract under test, per scene (issue #10 items 5-6, issue #11):
//   * the fit (RunFitRequest with the command line's default request) returns a camera or throws
//     SceneError (exit 3) with a reason other than kNumerical ("a bug"); nothing else -- another
//     exception would be exit 2 with an internal message on a well-formed file;
//   * a returned camera passed the consistency gate and its printed rms_px is the RMS a reader of
//     the camera file recomputes over the kept points (all in front of it), to 1e-12 relative
//     (the order of the sum: fit_auto_stress_test.cc, kRmsRelative), and exactly the same from
//     the camera file text (which writes round-tripping doubles);
//   * the camera file holds no non-finite number (no null, nan or inf in its JSON);
//   * every export format writes text without a non-finite number, or refuses the camera with
//     std::invalid_argument (e.g. colmap and skew).
// A violated check prints what differs and aborts, so libFuzzer saves the input.
//
// Build and run: scripts/fuzz.sh. CAMPROJ_FUZZ_DUMP=FILE writes each scene run as a points file
// (its first line says the image size), to refit a finding with `camproj fit`.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "camproj/camera.h"
#include "camproj/camera_file.h"
#include "camproj/errors.h"
#include "camproj/export.h"
#include "camproj/fit.h"
#include "camproj/fit_request.h"
#include "camproj/library_logging.h"
#include "camproj/model_select.h"

namespace {

using camproj::Camera;
using camproj::FitResult;

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "fit_scene_fuzzer: contract violated: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// fit_auto_stress_test.cc's kRmsRelative: the printed and the recomputed RMS sum the same
// per-point pixels in another order, (N + 2) u <= 1.4e-14 relative; 1e-12 with a margin.
constexpr double kRmsRelative = 1e-12;

struct Scene {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<std::string> ids;
  camproj::ImageSize size;
};

Scene MakeScene(FuzzedDataProvider& in) {
  Scene s;
  s.size.width = in.ConsumeIntegralInRange<int>(16, 4000);
  s.size.height = in.ConsumeIntegralInRange<int>(16, 4000);
  const int n = in.ConsumeIntegralInRange<int>(4, 24);
  const bool through_camera = in.ConsumeIntegralInRange<int>(0, 3) != 0;
  // A camera at `distance` (in grid units) looking at the origin from a direction on the sphere.
  const double fovy_deg = in.ConsumeFloatingPointInRange<double>(2.0, 170.0);
  const double distance = std::ldexp(1.0, in.ConsumeIntegralInRange<int>(-2, 12));
  const double azimuth = in.ConsumeFloatingPointInRange<double>(-M_PI, M_PI);
  const double elevation = in.ConsumeFloatingPointInRange<double>(-1.5, 1.5);
  const double shift_x = in.ConsumeFloatingPointInRange<double>(-1.0, 1.0);
  const double shift_y = in.ConsumeFloatingPointInRange<double>(-1.0, 1.0);
  const Eigen::Vector3d eye =
      distance * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                 std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  const Eigen::Vector3d forward = -eye.normalized();
  Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ());
  if (right.norm() < 1e-6) right = Eigen::Vector3d::UnitX();
  right.normalize();
  const Eigen::Vector3d down = forward.cross(right);
  const double f = 0.5 * s.size.height / std::tan(0.5 * fovy_deg * M_PI / 180.0);
  const Eigen::Vector2d principal(0.5 * (s.size.width - 1) * (1.0 + shift_x),
                                  0.5 * (s.size.height - 1) * (1.0 + shift_y));
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d x;
    for (int c = 0; c < 3; ++c) x(c) = in.ConsumeIntegralInRange<int>(-8, 8) / 8.0;
    Eigen::Vector2d pixel;
    const Eigen::Vector3d in_cam(right.dot(x - eye), down.dot(x - eye), forward.dot(x - eye));
    if (through_camera && in_cam.z() > 1e-9 && in.ConsumeIntegralInRange<int>(0, 15) != 0) {
      pixel = principal + f * in_cam.head<2>() / in_cam.z();
      pixel += Eigen::Vector2d(in.ConsumeIntegralInRange<int>(-16, 16),
                               in.ConsumeIntegralInRange<int>(-16, 16)) / 16.0;  // noise
    } else {  // arbitrary, or a mis-click: anywhere in or around the image
      pixel = Eigen::Vector2d(in.ConsumeFloatingPointInRange<double>(-s.size.width, 2.0 * s.size.width),
                              in.ConsumeFloatingPointInRange<double>(-s.size.height, 2.0 * s.size.height));
    }
    if (!pixel.allFinite() || pixel.cwiseAbs().maxCoeff() > 1e12) pixel.setZero();
    s.points.push_back(x);
    s.pixels.push_back(pixel);
    s.ids.push_back("p" + std::to_string(i + 1));
  }
  const double scale = std::ldexp(1.0, in.ConsumeIntegralInRange<int>(-200, 200));
  const double offset =
      in.ConsumeBool() ? std::ldexp(1.0, in.ConsumeIntegralInRange<int>(0, 60)) : 0.0;
  const Eigen::Vector3d direction(in.ConsumeIntegralInRange<int>(-4, 4),
                                  in.ConsumeIntegralInRange<int>(-4, 4), 1.0);
  for (Eigen::Vector3d& x : s.points) x = scale * (x + offset * direction);
  return s;
}

// A JSON document's non-finite number: nlohmann writes one as null (strings are not numbers:
// a message may say "inf" in words). The one null that means something else: the three export's
// "world_origin": null, no world origin (world_origin.h).
bool HasNull(const nlohmann::json& value) {
  if (value.is_null()) return true;
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) {
      if (key == "world_origin" && item.is_null()) continue;
      if (HasNull(item)) return true;
    }
  } else if (value.is_array()) {
    for (const nlohmann::json& item : value) {
      if (HasNull(item)) return true;
    }
  }
  return false;
}

// A non-finite number in an export's text: nan, inf, infinity or null as a word (C printf,
// JavaScript, JSON), in any case.
bool HasNonFinite(const std::string& text) {
  static const std::regex word("(^|[^A-Za-z_])(nan|inf|infinity|null)([^A-Za-z_]|$)",
                               std::regex::icase);
  return std::regex_search(text, word);
}

// RMS over the kept points as a reader of the camera file computes it.
double RecomputedRms(const Camera& camera, const Scene& s, const std::vector<bool>& kept) {
  double sum_squares = 0.0;
  int count = 0;
  for (size_t i = 0; i < s.points.size(); ++i) {
    if (!kept[i]) continue;
    const std::optional<Eigen::Vector2d> pixel = camproj::PixelFromWorld(camera, s.points[i]);
    if (!pixel) Fail("kept point " + std::to_string(i) + " is not in front of the camera");
    sum_squares += (*pixel - s.pixels[i]).squaredNorm();
    ++count;
  }
  return std::sqrt(sum_squares / count);
}

void CheckCamera(const FitResult& fit, const Scene& s) {
  if (!fit.consistency.checked || !fit.consistency.passed) {
    Fail("returned a camera that did not pass the gate: " + fit.consistency.summary);
  }
  std::vector<bool> kept(s.points.size(), true);
  for (const int i : fit.outliers) {
    if (i < 0 || i >= static_cast<int>(kept.size()) || !kept[i]) {
      Fail("outlier index " + std::to_string(i) + " is out of range or repeated");
    }
    kept[i] = false;
  }
  const double rms = RecomputedRms(fit.camera, s, kept);
  if (!(std::abs(fit.rms_px - rms) <= kRmsRelative * rms)) {
    char text[128];
    std::snprintf(text, sizeof text, "printed rms %.17g px, recomputed %.17g px", fit.rms_px, rms);
    Fail(text);
  }
  const std::string file = camproj::FitCameraFileText(fit, camproj::PixelOrigin::kCenter);
  if (HasNull(nlohmann::json::parse(file))) {
    Fail("the camera file holds a non-finite number (null):\n" + file);
  }
  const Camera read_back = camproj::CameraFromJsonText(file, "fuzzed camera file");
  if (RecomputedRms(read_back, s, kept) != rms) Fail("the camera file's camera has another RMS");
  for (const camproj::ExportFormat format :
       {camproj::ExportFormat::kGl, camproj::ExportFormat::kGlm, camproj::ExportFormat::kOpenCvYaml,
        camproj::ExportFormat::kColmap, camproj::ExportFormat::kThree,
        camproj::ExportFormat::kJson, camproj::ExportFormat::kGlsl,
        camproj::ExportFormat::kDistortionMesh}) {
    try {
      const std::string text = camproj::ExportCamera(read_back, format);
      const bool json = format == camproj::ExportFormat::kJson ||
                        format == camproj::ExportFormat::kThree ||
                        format == camproj::ExportFormat::kDistortionMesh;
      if (json ? HasNull(nlohmann::json::parse(text)) : HasNonFinite(text)) {
        Fail(std::string("export ") + camproj::ToString(format) + " wrote a non-finite number:\n" +
             text);
      }
    } catch (const std::invalid_argument&) {
      // A camera the format cannot represent, refused with the reason.
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (camproj::SetLibraryLogging(false), true);
  (void)quiet;
  FuzzedDataProvider in(data, size);
  const Scene s = MakeScene(in);
  if (const char* dump = std::getenv("CAMPROJ_FUZZ_DUMP")) {
    // The scene as a points file for `camproj fit` (reproducing a finding outside the fuzzer).
    if (FILE* out = std::fopen(dump, "w")) {
      std::fprintf(out, "# image size %dx%d\nid,X,Y,Z,u,v\n", s.size.width, s.size.height);
      for (size_t i = 0; i < s.points.size(); ++i) {
        std::fprintf(out, "%s,%.17g,%.17g,%.17g,%.17g,%.17g\n", s.ids[i].c_str(), s.points[i].x(),
                     s.points[i].y(), s.points[i].z(), s.pixels[i].x(), s.pixels[i].y());
      }
      std::fclose(out);
    }
  }
  const camproj::FitRequest request = camproj::FitRequestFrom(camproj::FitArguments(), s.size);
  try {
    CheckCamera(camproj::RunFitRequest(s.points, s.pixels, s.ids, s.size, request), s);
  } catch (const camproj::SceneError& e) {
    if (e.reason() == camproj::SceneError::Reason::kNumerical) {
      Fail(std::string("refused as a numerical failure (a bug): ") + e.what());
    }
  }
  return 0;
}
