#include "camproj/camera_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/world_origin.h"
#include "check.h"

namespace camproj {

using json = nlohmann::json;

// Deepest nesting of arrays and objects a camera file may have: the files camproj writes nest 5
// deep (document > fit > selection > candidates > candidate).
constexpr int kMaxJsonDepth = 32;
// A calibration file takes about 2.9 KB per view: 16 MiB holds ~5800 views (a 500-frame sequence
// is 1.4 MB) and still refuses a wrong file before parsing it.
constexpr size_t kMaxCalibrationFileBytes = size_t{16} << 20;

namespace {

// What a value is, for a message: its type and size, or a short scalar. Never the value's
// subtree: dump() recurses once per nesting level and would quote a hostile file back.
std::string Describe(const json& value) {
  switch (value.type()) {
    case json::value_t::object:
      return "an object of " + std::to_string(value.size()) + " members";
    case json::value_t::array:
      return "an array of " + std::to_string(value.size()) + " elements";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return value.get<bool>() ? "true" : "false";
    case json::value_t::null:
      return "null";
    default:
      return "a number";
  }
}

// Reads typed values out of a parsed document, naming the source and key path on failure.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw InputError(source_ + ": " + key + ": " + what);
  }

  const json& Member(const json& parent, const std::string& parent_key,
                     const std::string& name) const {
    const std::string key = parent_key.empty() ? name : parent_key + "." + name;
    if (!parent.is_object()) Fail(parent_key.empty() ? "(top level)" : parent_key, "expected an object");
    const auto it = parent.find(name);
    if (it == parent.end()) Fail(key, "missing");
    return *it;
  }

  double Number(const json& value, const std::string& key) const {
    if (!value.is_number()) Fail(key, "expected a number, got " + Describe(value));
    const double number = value.get<double>();
    if (!std::isfinite(number)) Fail(key, "expected a finite number");
    return number;
  }

  double NumberOr(const json& parent, const std::string& parent_key, const std::string& name,
                  double fallback) const {
    if (!parent.contains(name)) return fallback;
    return Number(parent.at(name), parent_key + "." + name);
  }

  Eigen::VectorXd Vector(const json& value, const std::string& key, int size) const {
    if (!value.is_array() || static_cast<int>(value.size()) != size) {
      Fail(key, "expected an array of " + std::to_string(size) + " numbers, got " + Describe(value));
    }
    Eigen::VectorXd vector(size);
    for (int i = 0; i < size; ++i) {
      vector[i] = Number(value[static_cast<size_t>(i)], key + "[" + std::to_string(i) + "]");
    }
    return vector;
  }

 private:
  std::string source_;
};

json Vector3Json(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json Matrix4Json(const Eigen::Matrix4d& m) {
  json numbers = json::array();
  for (int i = 0; i < 16; ++i) numbers.push_back(m.data()[i]);  // column-major
  return numbers;
}

json FarJson(double z_far) { return std::isinf(z_far) ? json("inf") : json(z_far); }

// The document's "image_size": [width, height], whole numbers in [1, kMaxImageSide].
ImageSize ReadImageSize(const json& document, const Reader& reader) {
  const Eigen::VectorXd size = reader.Vector(reader.Member(document, "", "image_size"), "image_size", 2);
  if (size[0] != std::floor(size[0]) || size[1] != std::floor(size[1]) || size[0] < 1 ||
      size[1] < 1 || size[0] > kMaxImageSide || size[1] > kMaxImageSide) {
    reader.Fail("image_size", internal::Concat("expected two positive integers (width, height), at most ",
                                               kMaxImageSide, " each"));
  }
  return {static_cast<int>(size[0]), static_cast<int>(size[1])};
}

// The document's "pixel_origin" (kCenter where absent).
PixelOrigin ReadPixelOrigin(const json& document, const Reader& reader) {
  PixelOrigin origin = PixelOrigin::kCenter;
  if (document.is_object() && document.contains("pixel_origin")) {
    const json& value = document.at("pixel_origin");
    if (!value.is_string()) reader.Fail("pixel_origin", "expected \"center\" or \"corner\"");
    try {
      origin = PixelOriginFromString(value.get<std::string>());
    } catch (const std::invalid_argument& e) {
      reader.Fail("pixel_origin", e.what());
    }
  }
  return origin;
}

// The intrinsics of a camera-file document, in kCenter.
Intrinsics ReadIntrinsics(const json& document, const Reader& reader) {
  const PixelOrigin origin = ReadPixelOrigin(document, reader);

  const json& k = reader.Member(document, "", "intrinsics");
  Intrinsics intrinsics;
  intrinsics.fx = reader.Number(reader.Member(k, "intrinsics", "fx"), "intrinsics.fx");
  intrinsics.fy = reader.Number(reader.Member(k, "intrinsics", "fy"), "intrinsics.fy");
  intrinsics.cx = reader.Number(reader.Member(k, "intrinsics", "cx"), "intrinsics.cx");
  intrinsics.cy = reader.Number(reader.Member(k, "intrinsics", "cy"), "intrinsics.cy");
  intrinsics.skew = reader.NumberOr(k, "intrinsics", "skew", 0.0);
  intrinsics.k1 = reader.NumberOr(k, "intrinsics", "k1", 0.0);
  intrinsics.k2 = reader.NumberOr(k, "intrinsics", "k2", 0.0);
  intrinsics.p1 = reader.NumberOr(k, "intrinsics", "p1", 0.0);
  intrinsics.p2 = reader.NumberOr(k, "intrinsics", "p2", 0.0);
  intrinsics.k3 = reader.NumberOr(k, "intrinsics", "k3", 0.0);
  try {
    intrinsics.Check();
  } catch (const std::invalid_argument& e) {
    reader.Fail("intrinsics", e.what());
  }
  return ConvertPixelOrigin(intrinsics, origin, PixelOrigin::kCenter);
}

// Throws InputError if arrays and objects nest deeper than kMaxJsonDepth anywhere in `text`, or
// a number is beyond a double's range (naming its line, which the parser's message does not).
// Runs before the parser, so nothing recursive ever sees a deeper document: a linear scan that
// skips strings (a bracket inside a string does not nest).
void RequireShallowJson(const std::string& text, const std::string& source) {
  int depth = 0;
  bool in_string = false;
  size_t line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) {
        throw InputError(source + ": line " + std::to_string(line) + ": arrays and objects nest deeper than " +
                         std::to_string(kMaxJsonDepth) + " levels");
      }
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      // A number the parser would read as 0 (1e-400) or refuse without a line (1e400).
      size_t end = i;
      while (end < text.size() && std::strchr("0123456789+-.eE", text[end]) != nullptr) ++end;
      double value = 0.0;
      if (std::from_chars(text.data() + i, text.data() + end, value).ec == std::errc::result_out_of_range) {
        const std::string number = text.substr(i, end - i);
        const size_t exponent = number.find_first_of("eE");
        const bool tiny = exponent != std::string::npos && number[exponent + 1] == '-';
        throw InputError(source + ": line " + std::to_string(line) + ": the number " + number +
                         " is out of the range of a double" + (tiny ? " (too small: it would read as 0)" : ""));
      }
      i = end - 1;
    }
  }
}

json ParseJson(const std::string& text, const std::string& source) {
  RequireShallowJson(text, source);
  // A key given twice in one object: the parser keeps the last silently, so a file edited by
  // hand ("image_size" twice) would be read as the writer did not mean. Refused, naming it.
  std::vector<std::set<std::string>> keys_of_open_objects;
  const json::parser_callback_t refuse_duplicate_keys = [&](int /*depth*/, json::parse_event_t event,
                                                            json& parsed) {
    if (event == json::parse_event_t::object_start) keys_of_open_objects.emplace_back();
    if (event == json::parse_event_t::object_end) keys_of_open_objects.pop_back();
    if (event == json::parse_event_t::key &&
        !keys_of_open_objects.back().insert(parsed.get<std::string>()).second) {
      throw InputError(source + ": key \"" + parsed.get<std::string>() +
                       "\" appears twice in one object: keep one");
    }
    return true;
  };
  try {
    return json::parse(text, refuse_duplicate_keys);
  } catch (const json::parse_error& e) {
    // nlohmann's message names the line and column of the syntax error.
    throw InputError(source + ": not valid JSON: " + e.what());
  } catch (const json::exception& e) {
    // E.g. a number beyond a double's range ("1e400"): out_of_range, not a parse_error.
    throw InputError(source + ": invalid JSON: " + e.what());
  }
}

}  // namespace

void CameraFileOptions::Check() const {
  internal::Require(std::isfinite(target_distance) && target_distance > 0.0,
                    "target distance must be finite and positive, got ", target_distance);
}

namespace {

// A camera file's document, or a calibration file's views[i].camera.
Camera CameraFromDocument(const json& document, const Reader& reader) {
  Camera camera;
  camera.image_size = ReadImageSize(document, reader);

  camera.intrinsics = ReadIntrinsics(document, reader);
  if (document.contains("projection")) {
    const json& projection = document.at("projection");
    if (projection == "orthographic") {
      camera.projection = Projection::kOrthographic;
    } else if (projection != "perspective") {
      reader.Fail("projection", "expected \"perspective\" or \"orthographic\"");
    }
  }

  try {
    if (document.contains("cam_from_world")) {
      const json& pose = document.at("cam_from_world");
      const json& rows = reader.Member(pose, "cam_from_world", "R");
      if (!rows.is_array() || rows.size() != 3) reader.Fail("cam_from_world.R", "expected 3 rows");
      for (int r = 0; r < 3; ++r) {
        camera.cam_from_world.rotation.row(r) =
            reader.Vector(rows[static_cast<size_t>(r)], "cam_from_world.R[" + std::to_string(r) + "]", 3)
                .transpose();
      }
      camera.cam_from_world.translation =
          reader.Vector(reader.Member(pose, "cam_from_world", "t"), "cam_from_world.t", 3);
      camera.cam_from_world.Check();
    } else {
      const json& look = reader.Member(document, "", "look_at");
      LookAt look_at;
      look_at.eye = reader.Vector(reader.Member(look, "look_at", "eye"), "look_at.eye", 3);
      look_at.target = reader.Vector(reader.Member(look, "look_at", "target"), "look_at.target", 3);
      look_at.up = reader.Vector(reader.Member(look, "look_at", "up"), "look_at.up", 3);
      camera.cam_from_world = CamFromWorldFromLookAt(look_at);
    }
  } catch (const std::invalid_argument& e) {
    reader.Fail(document.contains("cam_from_world") ? "cam_from_world" : "look_at", e.what());
  }

  const json& frustum = reader.Member(document, "", "frustum");
  camera.z_near = reader.Number(reader.Member(frustum, "frustum", "near"), "frustum.near");
  const json& far = reader.Member(frustum, "frustum", "far");
  if (far.is_string() && far.get<std::string>() == "inf") {
    camera.z_far = kInfinity;
  } else {
    camera.z_far = reader.Number(far, "frustum.far");
  }
  if (document.contains("world_origin")) {
    camera.world_origin = reader.Vector(document.at("world_origin"), "world_origin", 3);
  }
  try {
    camera.Check();
  } catch (const std::invalid_argument& e) {
    reader.Fail("frustum", e.what());
  }
  if (camera.world_origin) {
    // C - origin can overflow (the view matrix's translation is built from it, then checked).
    bool finite = false;
    try {
      finite = GlEyeFromOriginWorld(camera.cam_from_world, *camera.world_origin).allFinite();
    } catch (const std::invalid_argument&) {
    }
    if (!finite) {
      reader.Fail("world_origin", "the view matrix relative to it is not finite: the values are "
                                  "too large for a double");
    }
  }
  // The derived views, checked by what they come from: the look-at (eye = -R^T t) from the pose
  // alone, the rest from the intrinsics with near and far.
  const std::string pose_key = document.contains("cam_from_world") ? "cam_from_world" : "look_at";
  try {
    LookAtFromCamFromWorld(camera.cam_from_world);
  } catch (const std::invalid_argument& e) {
    reader.Fail(pose_key, e.what());
  }
  try {
    RequireFiniteViews(camera);
  } catch (const std::invalid_argument& e) {
    reader.Fail("intrinsics with frustum.near, frustum.far", e.what());
  }
  return camera;
}

// A name from a file, for a message: cut short like any quoted file text.
std::string ShortName(const std::string& name) {
  constexpr size_t kMaxBytes = 60;
  return name.size() > kMaxBytes ? name.substr(0, kMaxBytes) + "..." : name;
}

// The `name` strings of a calibration file's views (or refused_views) array.
std::vector<std::string> ViewNames(const json& document, const char* key) {
  std::vector<std::string> names;
  if (!document.contains(key) || !document.at(key).is_array()) return names;
  for (const json& view : document.at(key)) {
    if (view.is_object() && view.contains("name") && view.at("name").is_string()) {
      names.push_back(view.at("name").get<std::string>());
    }
  }
  return names;
}

bool IsCalibrationFile(const json& document) {
  return document.is_object() && document.contains("views") && document.at("views").is_array() &&
         !document.contains("look_at") && !document.contains("cam_from_world");
}

}  // namespace

Camera CameraFromJsonText(const std::string& text, const std::string& source) {
  const json document = ParseJson(text, source);
  if (IsCalibrationFile(document)) {
    throw InputError(source + ": a calibration file of " +
                     std::to_string(document.at("views").size()) +
                     " views, not one camera: select a view by its name (camproj export and "
                     "project: --view NAME)");
  }
  return CameraFromDocument(document, Reader(source));
}

// The `camera` object of the entry of a calibration file's `views` named `view`, and the reader
// whose messages name it ("SOURCE, view NAME"). Throws InputError as CalibrationViewFromJsonText
// says.
std::pair<const json*, Reader> CalibrationViewCamera(const json& document,
                                                     const std::string& source,
                                                     const std::string& view) {
  if (!IsCalibrationFile(document)) {
    throw InputError(source + ": not a calibration file (no views array): a view is selected "
                              "only in the file camproj calibrate writes");
  }
  for (const json& entry : document.at("views")) {
    if (entry.is_object() && entry.contains("name") && entry.at("name") == view) {
      Reader reader(source + ", view " + ShortName(view));
      const json* camera = &reader.Member(entry, "", "camera");
      return {camera, std::move(reader)};
    }
  }
  const std::vector<std::string> refused = ViewNames(document, "refused_views");
  if (std::find(refused.begin(), refused.end(), view) != refused.end()) {
    throw InputError(source + ": view " + ShortName(view) +
                     " was refused by the calibration (refused_views): it has no camera");
  }
  const std::vector<std::string> names = ViewNames(document, "views");
  constexpr size_t kMaxListed = 10;
  std::string listed;
  for (size_t i = 0; i < names.size() && i < kMaxListed; ++i) {
    listed += (i == 0 ? "" : ", ") + ShortName(names[i]);
  }
  if (names.size() > kMaxListed) listed += ", ... (" + std::to_string(names.size()) + " in all)";
  throw InputError(source + ": no view named " + ShortName(view) + "; the views are " +
                   (listed.empty() ? "none" : listed));
}

PixelOrigin CameraFilePixelOrigin(const std::string& text, const std::string& source,
                                  const std::string& view) {
  const json document = ParseJson(text, source);
  if (view.empty()) return ReadPixelOrigin(document, Reader(source));
  const auto [camera, reader] = CalibrationViewCamera(document, source, view);
  return ReadPixelOrigin(*camera, reader);
}

Camera CalibrationViewFromJsonText(const std::string& text, const std::string& source,
                                   const std::string& view) {
  const json document = ParseJson(text, source);
  const auto [camera, reader] = CalibrationViewCamera(document, source, view);
  return CameraFromDocument(*camera, reader);
}

Camera ReadCalibrationView(const std::string& path, const std::string& view) {
  return CalibrationViewFromJsonText(ReadWholeFile(path, kMaxCalibrationFileBytes), path, view);
}

Intrinsics IntrinsicsFromJsonText(const std::string& text, const std::string& source,
                                  std::optional<ImageSize>* image_size) {
  const json document = ParseJson(text, source);
  const Reader reader(source);
  const Intrinsics intrinsics = ReadIntrinsics(document, reader);
  // An orthographic camera's fx, fy are px per world unit, not a focal length: taken for a
  // pinhole's, a pose fit from them was refused as mismatched points.
  if (document.is_object() && document.contains("projection") &&
      document.at("projection") != "perspective") {
    reader.Fail("projection", document.at("projection") == "orthographic"
                                  ? "an orthographic camera's intrinsics (px per world unit) are "
                                    "not a pinhole's: give a perspective camera or a calibration"
                                  : "expected \"perspective\" or \"orthographic\"");
  }
  if (image_size != nullptr) {
    *image_size = std::nullopt;
    if (document.is_object() && document.contains("image_size")) {
      *image_size = ReadImageSize(document, reader);
    }
  }
  return intrinsics;
}

Intrinsics ReadIntrinsicsFile(const std::string& path, std::optional<ImageSize>* image_size) {
  // Also a calibration file's intrinsics (`camproj fit --intrinsics CALIB.json`).
  return IntrinsicsFromJsonText(ReadWholeFile(path, kMaxCalibrationFileBytes), path, image_size);
}

std::vector<int> OutlierIndicesFromJsonText(const std::string& text, const std::string& source) {
  const auto document = ParseJson(text, source);
  std::vector<int> outliers;
  if (!document.is_object() || !document.contains("fit") || !document["fit"].is_object() ||
      !document["fit"].contains("outliers")) {
    return outliers;
  }
  const auto& list = document["fit"]["outliers"];
  if (!list.is_array()) throw InputError(source + ": fit.outliers must be an array of indices");
  for (size_t i = 0; i < list.size(); ++i) {
    if (!list[i].is_number_integer() || list[i].get<int64_t>() < 0 ||
        list[i].get<int64_t>() > std::numeric_limits<int>::max()) {
      throw InputError(internal::Concat(source, ": fit.outliers[", i,
                                        "] must be a non-negative integer index"));
    }
    outliers.push_back(list[i].get<int>());
  }
  return outliers;
}

Camera ReadCameraFile(const std::string& path) {
  // A camera file is a few kilobytes; a megabyte bound refuses a wrong file early.
  return CameraFromJsonText(ReadWholeFile(path, size_t{1} << 20), path);
}

namespace {

// The camera's own part of the file: image, intrinsics in options.pixel_origin, pose, look-at,
// frustum or ortho box, perspective, GL matrices, world origin.
json CameraJson(const Camera& camera, const CameraFileOptions& options) {
  const CameraViews views = ViewsOfCamera(camera, options.target_distance, options.depth);
  const Intrinsics k =
      ConvertPixelOrigin(camera.intrinsics, PixelOrigin::kCenter, options.pixel_origin);
  json document;
  document["image_size"] = {camera.image_size.width, camera.image_size.height};
  document["pixel_origin"] = ToString(options.pixel_origin);
  const bool orthographic = camera.projection == Projection::kOrthographic;
  document["projection"] = orthographic ? "orthographic" : "perspective";
  document["intrinsics"] = {{"fx", k.fx}, {"fy", k.fy},     {"cx", k.cx}, {"cy", k.cy},
                            {"skew", k.skew}, {"k1", k.k1}, {"k2", k.k2}};
  if (k.HasBeyondTwoRadial()) {
    document["intrinsics"]["p1"] = k.p1;
    document["intrinsics"]["p2"] = k.p2;
    document["intrinsics"]["k3"] = k.k3;
  }
  json rows = json::array();
  for (int r = 0; r < 3; ++r) {
    rows.push_back(Vector3Json(camera.cam_from_world.rotation.row(r).transpose()));
  }
  document["cam_from_world"] = {{"R", rows}, {"t", Vector3Json(camera.cam_from_world.translation)}};
  document["look_at"] = {{"eye", Vector3Json(views.look_at.eye)},
                         {"target", Vector3Json(views.look_at.target)},
                         {"up", Vector3Json(views.look_at.up)}};
  if (orthographic) {
    document["frustum"] = {{"near", camera.z_near}, {"far", camera.z_far},
                           {"note", "orthographic: no frustum; fx, fy, skew are px per world unit"}};
    if (views.ortho) {
      const Ortho& o = *views.ortho;
      document["ortho"] = {{"left", o.left}, {"right", o.right}, {"bottom", o.bottom},
                           {"top", o.top},   {"near", o.z_near}, {"far", o.z_far}};
    }
  } else if (views.frustum) {
    const Frustum& f = *views.frustum;
    document["frustum"] = {{"left", f.left}, {"right", f.right}, {"bottom", f.bottom},
                           {"top", f.top},   {"near", f.z_near}, {"far", FarJson(f.z_far)}};
  } else {
    // Skew has no glFrustum form; near and far still define the export's depth range.
    document["frustum"] = {{"near", camera.z_near}, {"far", FarJson(camera.z_far)},
                           {"note", "skew != 0 has no glFrustum form: use gl.projection"}};
  }
  if (views.perspective) {
    document["perspective"] = {{"fovy_deg", views.perspective->fovy_deg},
                               {"aspect", views.perspective->aspect}};
  }
  document["gl"] = {{"projection", Matrix4Json(views.clip_from_gl_eye)},
                    {"view", Matrix4Json(views.gl_eye_from_world)},
                    {"depth", ToString(options.depth.clip_depth)},
                    {"reversed_z", options.depth.reversed_z}};
  if (camera.world_origin) {
    document["world_origin"] = Vector3Json(*camera.world_origin);
    document["gl"]["view_relative_to_origin"] = Matrix4Json(views.gl_eye_from_origin_world);
  }
  if (camera.intrinsics.HasDistortion()) {
    document["gl"]["note"] = "the projection matrix is the pinhole part: the lens (" +
                             DistortionText(k) + ") is not in it";
  }
  return document;
}

// The camera file's `fit` record: residuals, left-out points, the checks, the model and its
// selection, the parameters' sigmas, the linearity check, the time.
json FitRecordJson(const FitRecord& fit) {
  json record;
  record["rms_px"] = fit.rms_px;
  record["median_px"] = fit.median_px;
  record["max_px"] = fit.max_px;
  record["num_points"] = fit.num_points;
  if (!fit.outliers.empty()) {
    record["outliers"] = fit.outliers;
    record["outlier_method"] = fit.outlier_method;
    json points = json::array();
    for (const FitRecord::OutlierPoint& p : fit.outlier_points) {
      // A left-out point behind the camera has no pixel, so no residual: said, not written
      // as a non-finite number.
      points.push_back({{"index", p.index}});
      if (std::isfinite(p.residual_px)) {
        points.back()["residual_px"] = p.residual_px;
      } else {
        points.back()["behind_camera"] = true;
      }
      if (p.rms_with_px > 0.0 && std::isfinite(p.rms_with_px)) {
        points.back()["rms_with_px"] = p.rms_with_px;
      }
    }
    if (!points.empty()) record["outlier_points"] = points;
  }
  if (!fit.consistency.empty()) record["consistency"] = fit.consistency;
  if (!fit.determination.empty()) record["determination"] = fit.determination;
  if (!fit.reliability.empty()) record["reliability"] = fit.reliability;
  record["start"] = fit.start;
  record["model"] = fit.model;
  if (!fit.candidates.empty()) {
    json selection;
    selection["criterion"] = fit.criterion;
    selection["sigma_px"] = fit.selection_sigma_px;
    selection["candidates"] = json::array();
    for (const FitRecord::Candidate& c : fit.candidates) {
      json candidate = {{"name", c.name}, {"verdict", c.verdict}};
      if (c.num_params > 0) {
        candidate["num_params"] = c.num_params;
        candidate["rms_px"] = c.rms_px;
        candidate["criterion"] = c.criterion;
      }
      selection["candidates"].push_back(candidate);
    }
    record["selection"] = selection;
  }
  record["free"] = fit.free;
  record["fixed"] = json::array();
  for (const auto& [name, value] : fit.fixed) record["fixed"].push_back({{"name", name}, {"value", value}});
  record["left_out"] = json::array();
  for (const auto& [name, why] : fit.left_out) record["left_out"].push_back({{"name", name}, {"why", why}});
  record["sigma"] = json::object();
  for (const auto& [name, sigma] : fit.sigma) record["sigma"][name] = sigma;
  record["pixel_sigma"] = fit.pixel_sigma;
  record["pixel_sigma_estimated"] = fit.pixel_sigma_estimated;
  record["iterations"] = fit.iterations;
  record["jacobian_condition"] = fit.jacobian_condition;
  if (fit.linearity.checked) {
    const LinearityCheck& l = fit.linearity;
    // An unbounded deviation (a point crosses behind the camera within the region) is said
    // as "unbounded": true, without the number: the file holds no non-finite number.
    record["linearity"] = {{"linear", l.linear}, {"level", l.level}, {"bound", l.bound},
                           {"worst_direction", l.worst_direction},
                           {"unbounded", !std::isfinite(l.worst_deviation)}};
    if (std::isfinite(l.worst_deviation)) record["linearity"]["worst_deviation"] = l.worst_deviation;
  }
  record["time_ms"] = fit.time_ms;
  return record;
}

}  // namespace

std::string CameraToJsonText(const Camera& camera, const CameraFileOptions& options,
                             const FitRecord* fit) {
  options.Check();
  RequireFiniteViews(camera, options.depth);
  json document = CameraJson(camera, options);
  if (fit != nullptr) document["fit"] = FitRecordJson(*fit);
  return document.dump(2) + "\n";
}

}  // namespace camproj
