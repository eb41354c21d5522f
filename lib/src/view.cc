#include "camproj/view.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "camproj/camera_file.h"
#include "camproj/errors.h"
#include "camproj/export.h"
#include "camproj/file_io.h"
#include "camproj/image_header.h"
#include "check.h"
#include "drawing.h"
#include "image_codecs.h"
#include "photo.h"
#include "view/assets.h"
#include "view/obj_mesh.h"

namespace camproj {

void ViewOptions::Check() const {}

namespace {

using nlohmann::json;
using internal::Concat;

constexpr size_t kMaxMeshFileBytes = size_t{1} << 30;

std::string Base64(std::string_view bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t n = (uint32_t{static_cast<uint8_t>(bytes[i])} << 16) |
                       (uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8) |
                       uint32_t{static_cast<uint8_t>(bytes[i + 2])};
    out += kDigits[n >> 18];
    out += kDigits[(n >> 12) & 63];
    out += kDigits[(n >> 6) & 63];
    out += kDigits[n & 63];
  }
  if (i < bytes.size()) {
    uint32_t n = uint32_t{static_cast<uint8_t>(bytes[i])} << 16;
    if (i + 1 < bytes.size()) n |= uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8;
    out += kDigits[n >> 18];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
json Vec(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }

// The page's frame: the world moved so that the eye is its origin. The page's buffers are
// float32 (WebGL's): survey coordinates (UTM, 5e5 m) held to 0.03 m put points 10-16 px off in
// the view through the camera, before session 43; about the eye they keep float32's 6e-8
// relative to the scene's size. Every `*_in_page` of the page's data is point_in_world - origin.
struct PageFrame {
  Eigen::Vector3d origin_in_world;
  json operator()(const Eigen::Vector3d& point_in_world) const {
    return Vec(Eigen::Vector3d(point_in_world - origin_in_world));
  }
};

// The cam-frame point at `depth` (z_cam) whose pixel is `pixel` (kCenter), through `intrinsics`
// (distortion inverted when present); for an orthographic camera the parallel ray's point.
Eigen::Vector3d PointInCamAtDepth(const Camera& camera, const Intrinsics& intrinsics,
                                  const Eigen::Vector2d& pixel, double depth) {
  if (camera.projection == Projection::kOrthographic) {
    const double y = (pixel.y() - intrinsics.cy) / intrinsics.fy;
    const double x = (pixel.x() - intrinsics.cx - intrinsics.skew * y) / intrinsics.fx;
    return {x, y, depth};
  }
  return CamRayFromPixel(intrinsics, pixel) * depth;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The page's data: everything the script draws, computed here so that the script holds no
// geometry beyond three.js's rendering (and the pixel-origin shift).
// One point as the page draws it: where it is, where it was seen, the observed pixel's ray,
// and where the camera puts it (with and without the lens; none behind the camera).
// `ray_depth_behind` is the depth its ray is drawn to when the point is behind the camera;
// `max_distortion_px` gets the largest lens displacement seen.
json PointJson(const Camera& camera, const PageFrame& in_page,
               const Correspondences& correspondences, size_t i, bool outlier,
               double ray_depth_behind, double* max_distortion_px, ViewStats& stats) {
  const Eigen::Vector3d& x = correspondences.points_in_world[i];
  const Eigen::Vector2d& observed = correspondences.pixels[i];
  const double depth = (camera.cam_from_world * x).z();
  const std::optional<Eigen::Vector2d> predicted = PixelFromWorld(camera, x);
  json point = {{"id", correspondences.ids[i]},
                {"point_in_page", in_page(x)},
                {"observed_px", Vec(observed)},
                {"outlier", outlier}};
  ++stats.points;
  // The observed pixel's ray, drawn from the eye to the point's depth (the median depth for a
  // point behind the camera); beyond the distortion's fold there is no ray.
  // An orthographic camera's rays are parallel: drawn from the near plane, not from the eye.
  try {
    const Rigid3 world_from_cam = Inverse(camera.cam_from_world);
    const double ray_depth = depth > 0.0 ? depth : ray_depth_behind;
    point["ray_start_in_page"] =
        camera.projection == Projection::kOrthographic
            ? in_page(world_from_cam *
                      PointInCamAtDepth(camera, camera.intrinsics, observed, camera.z_near))
            : in_page(world_from_cam.translation);
    point["ray_end_in_page"] =
        in_page(world_from_cam * PointInCamAtDepth(camera, camera.intrinsics, observed, ray_depth));
  } catch (const std::domain_error&) {
    point["ray_start_in_page"] = nullptr;
    point["ray_end_in_page"] = nullptr;
  }
  if (!predicted) {
    point["predicted_px"] = nullptr;
    point["residual_px"] = nullptr;
    ++(depth > 0.0 ? stats.no_pixel : stats.behind);  // in front: its pixel is beyond a double
    return point;
  }
  // The pinhole's pixel is finite where the lens's is (a lens that overflows has none).
  const Eigen::Vector2d linear =
      PixelFromWorld(Camera{camera.image_size, camera.intrinsics.Pinhole(), camera.cam_from_world,
                            camera.z_near, camera.z_far, camera.projection},
                     x)
          .value_or(*predicted);
  *max_distortion_px = std::max(*max_distortion_px, (linear - *predicted).norm());
  point["predicted_px"] = Vec(*predicted);
  point["predicted_linear_px"] = Vec(linear);
  point["residual_px"] = (*predicted - observed).norm();
  const bool inside = PixelInImage(*predicted, camera.image_size);
  point["inside_image"] = inside;
  if (!inside) ++stats.outside_image;
  return point;
}

// The image plane at `depth` as the lens sees it: a grid of pixels from the image's outer
// corner to corner (kCenter -0.5 .. W - 0.5), each vertex on its pixel's ray (the lens inverted;
// with distortion the plane's edges bend where the linear frustum's are straight), with the
// photo's texture coordinate (v up) and two triangles per cell. A pinhole camera needs one cell;
// a lens gets kLensCells along the image's longer side, so that the photo's pixel is within
// a fraction of a pixel of its ray between vertices. A vertex beyond the lens's fold (no ray) is
// left out with its cells. `top_edge_in_page`: the top row's vertices (its first unbroken run);
// `outline_in_page`: the border as polylines round it, each unbroken (one closed loop, its first
// vertex repeated at its end, where every border vertex has a ray).
json ImagePlaneJson(const Camera& camera, const PageFrame& in_page, double depth) {
  constexpr int kLensCells = 48;
  const int w = camera.image_size.width;
  const int h = camera.image_size.height;
  const bool lens = camera.intrinsics.HasDistortion();
  const int cols = lens ? (w >= h ? kLensCells : std::max(2, kLensCells * w / h)) : 1;
  const int rows = lens ? (h >= w ? kLensCells : std::max(2, kLensCells * h / w)) : 1;
  const Rigid3 world_from_cam = Inverse(camera.cam_from_world);
  json positions = json::array(), uv = json::array(), index = json::array();
  // Each grid vertex's index in `positions`, -1 where it has no ray.
  std::vector<int> slot((cols + 1) * (rows + 1), -1);
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) {
      const double s = static_cast<double>(c) / cols, t = static_cast<double>(r) / rows;
      const Eigen::Vector2d pixel(-0.5 + s * w, -0.5 + t * h);
      try {
        const json p = in_page(world_from_cam *
                               PointInCamAtDepth(camera, camera.intrinsics, pixel, depth));
        slot[r * (cols + 1) + c] = static_cast<int>(positions.size());
        positions.push_back(p);
        uv.push_back({s, 1.0 - t});
      } catch (const std::domain_error&) {
        // beyond the lens's fold: no ray
      }
    }
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int a = slot[r * (cols + 1) + c], b = slot[r * (cols + 1) + c + 1];
      const int d = slot[(r + 1) * (cols + 1) + c], e = slot[(r + 1) * (cols + 1) + c + 1];
      if (a < 0 || b < 0 || d < 0 || e < 0) continue;
      index.push_back({a, b, e});
      index.push_back({a, e, d});
    }
  }
  // The border as polylines, broken where a vertex has no ray (a lens folding inside the image):
  // a missing stretch is not bridged by a chord the page would draw as the image's edge.
  std::vector<std::pair<int, int>> border;
  for (int c = 0; c < cols; ++c) border.emplace_back(0, c);
  for (int r = 0; r < rows; ++r) border.emplace_back(r, cols);
  for (int c = cols; c > 0; --c) border.emplace_back(rows, c);
  for (int r = rows; r > 0; --r) border.emplace_back(r, 0);
  // The vertex at (row, column), or null where it has no ray.
  const auto at = [&](int r, int c) -> const json* {
    const int k = slot[r * (cols + 1) + c];
    return k < 0 ? nullptr : &positions[k];
  };
  json outline = json::array(), top = json::array(), run = json::array();
  // Start at a vertex after a missing one (or anywhere where none is), so that no run wraps.
  const size_t m = border.size();
  size_t start = 0;
  const auto on_border = [&](size_t k) { return at(border[k % m].first, border[k % m].second); };
  for (size_t k = 0; k < m; ++k) {
    if (on_border(k) && !on_border(k + m - 1)) start = k;
  }
  bool whole = true;
  for (size_t k = 0; k < m; ++k) whole = whole && on_border(k) != nullptr;
  for (size_t k = 0; k <= m; ++k) {
    const json* p = on_border(start + k);
    if (p && (k < m || whole)) run.push_back(*p);
    if ((!p || k == m) && run.size() > 1) outline.push_back(run);
    if (!p || k == m) run = json::array();
  }
  for (int c = 0; c <= cols; ++c) {  // the top row, left to right, its first run
    const json* p = at(0, c);
    if (p) top.push_back(*p);
    if (!p && !top.empty()) break;
  }
  return {{"positions_in_page", positions}, {"uv", uv}, {"triangles", index},
          {"top_edge_in_page", top}, {"outline_in_page", outline}, {"through_lens", lens}};
}

// The frustum drawn: the GL camera's (linear) near plane, the image plane through the lens at
// the points' median depth (ImagePlaneJson), a far plane just beyond the farthest point (the
// camera's own far plane is often far beyond the scene).
json FrustumJson(const Camera& camera, const PageFrame& in_page, double median_depth,
                 double max_depth) {
  const int w = camera.image_size.width;
  const int h = camera.image_size.height;
  const Rigid3 world_from_cam = Inverse(camera.cam_from_world);
  const Intrinsics pinhole = camera.intrinsics.Pinhole();
  const double far_drawn = std::min(camera.z_far, std::max(1.25 * max_depth, 2.0 * camera.z_near));
  const double image_depth = std::clamp(median_depth, camera.z_near, far_drawn);
  const auto corners_at = [&](double depth) {
    json corners = json::array();
    const Eigen::Vector2d image_corners[4] = {
        {-0.5, -0.5}, {w - 0.5, -0.5}, {w - 0.5, h - 0.5}, {-0.5, h - 0.5}};
    for (const Eigen::Vector2d& c : image_corners) {
      corners.push_back(in_page(world_from_cam * PointInCamAtDepth(camera, pinhole, c, depth)));
    }
    return corners;
  };
  return {{"near", camera.z_near},
          {"far", std::isfinite(camera.z_far) ? json(camera.z_far) : json("inf")},
          {"far_drawn", far_drawn},
          {"image_depth", image_depth},
          {"near_corners_in_page", corners_at(camera.z_near)},
          {"image_plane", ImagePlaneJson(camera, in_page, image_depth)},
          {"far_corners_in_page", corners_at(far_drawn)}};
}

json SceneJson(const Camera& camera, const PageFrame& in_page,
               const std::vector<int>& outlier_indices,
               const Correspondences* correspondences, ViewStats& stats) {
  std::vector<bool> outlier(correspondences ? correspondences->pixels.size() : 0, false);
  json notes = json::array();
  for (const int i : outlier_indices) {
    if (static_cast<size_t>(i) < outlier.size()) {
      outlier[i] = true;
      ++stats.outliers;
    } else {
      notes.push_back(Concat("the fit's outlier index ", i, " is beyond the ", outlier.size(),
                             " points given: are they the points it was fitted to?"));
    }
  }
  // Depths of the points in front, for the image plane and the far plane drawn.
  std::vector<double> depths;
  if (correspondences) {
    for (const Eigen::Vector3d& x : correspondences->points_in_world) {
      const double z = (camera.cam_from_world * x).z();
      if (z > 0.0) depths.push_back(z);
    }
  }
  const double median_depth = depths.empty() ? std::clamp(1.0, camera.z_near, camera.z_far)
                                             : Median(depths);
  const double max_depth = depths.empty() ? median_depth
                                          : *std::max_element(depths.begin(), depths.end());
  json points = json::array();
  double max_distortion_px = 0.0;
  for (size_t i = 0; correspondences && i < correspondences->pixels.size(); ++i) {
    points.push_back(PointJson(camera, in_page, *correspondences, i, outlier[i], median_depth,
                               &max_distortion_px, stats));
  }
  if (max_distortion_px > 0.0) {
    notes.push_back(Concat(
        "three.js cameras are linear: the lens (", DistortionText(camera.intrinsics),
        ") is left out of the view through the camera, which moves the points there by up to ",
        std::round(max_distortion_px * 100) / 100, " px against camproj project"));
  }
  json scene = {{"image_size", {camera.image_size.width, camera.image_size.height}},
                {"projection", camera.projection == Projection::kOrthographic ? "orthographic"
                                                                               : "perspective"},
                {"page_origin_in_world", Vec(in_page.origin_in_world)},
                {"eye_in_page", in_page(Inverse(camera.cam_from_world).translation)},
                {"frustum", FrustumJson(camera, in_page, median_depth, max_depth)},
                {"image_depth_is_median", !depths.empty()},
                {"points", points},
                {"notes", notes}};
  ExportOptions export_options;  // depth "no": WebGLRenderer's clip volume
  // The page draws in its frame, so its camera is exported relative to the page's origin.
  Camera in_page_camera = camera;
  in_page_camera.world_origin = in_page.origin_in_world;
  scene["three"] = json::parse(ExportCamera(in_page_camera, ExportFormat::kThree, export_options));
  return scene;
}

// The photo as displayed (photo.h). A photo with an EXIF orientation is decoded, turned, and
// embedded re-encoded without one (a PNG as PNG, a JPEG at OpenCV's quality 95): the page's
// <img> applies the orientation but a WebGL texture need not, and the two views must show the
// pixels camproj overlay draws on. Before session 44 a JPEG turned a quarter was refused by its
// stored size and one turned half round was embedded as stored.
json ImageJson(const std::string& path, const Camera& camera) {
  const internal::Photo photo =
      internal::ReadPhoto(path, camera.image_size.width, camera.image_size.height);
  const bool png = photo.header.format == ImageFormat::kPng;
  const std::string data_url =
      std::string("data:") + (png ? "image/png" : "image/jpeg") + ";base64,";
  if (photo.header.exif_orientation == 1) {
    return {{"name", path}, {"data_url", data_url + Base64(photo.bytes)}};
  }
  std::vector<uchar> upright;
  if (!internal::EncodeImage(png ? ".png" : ".jpg", internal::DecodePhoto(photo), &upright)) {
    throw InputError(path + ": cannot re-encode the photo turned upright");
  }
  const std::string_view bytes(reinterpret_cast<const char*>(upright.data()), upright.size());
  return {{"name", path},
          {"exif_orientation", photo.header.exif_orientation},
          {"data_url", data_url + Base64(bytes)}};
}

json MeshJson(const std::string& path, const PageFrame& in_page, ViewStats& stats) {
  const internal::ObjMesh mesh = internal::ParseObjMesh(ReadWholeFile(path, kMaxMeshFileBytes), path);
  // ParseObjMesh skips the lines it does not know (OBJ has many): a file of none it knows is
  // not a mesh, and drawing nothing would hide that.
  if (mesh.triangles.empty()) {
    throw InputError(path + ": no faces (f lines with vertices from v lines): not an OBJ mesh");
  }
  stats.mesh_triangles = static_cast<int>(mesh.triangles.size() / 3);
  std::vector<double> positions_in_page = mesh.positions;
  for (size_t i = 0; i < positions_in_page.size(); ++i) {
    positions_in_page[i] -= in_page.origin_in_world[static_cast<int>(i % 3)];
  }
  return {{"name", path}, {"positions_in_page", positions_in_page}, {"triangles", mesh.triangles}};
}

// JSON inside a <script> element: '<' escaped so that no "</script" or "<!--" can end or change
// the element (it occurs only inside strings, where \u003c reads back as '<').
std::string ScriptSafeJson(const json& value) {
  const std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

// The template with each key (found once in it) replaced by its value, in one pass over the
// template: a value is never searched for keys (an id, a title or a camera name that reads
// "@CAMPROJ_PAGE_SCRIPT@" took that key's place in the page before session 37).
std::string FillTemplate(const std::string& page_template,
                         const std::vector<std::pair<std::string, std::string>>& keys_and_values) {
  std::vector<std::pair<size_t, size_t>> places;  // (position in the template, key index)
  for (size_t k = 0; k < keys_and_values.size(); ++k) {
    const std::string& key = keys_and_values[k].first;
    const size_t at = page_template.find(key);
    if (at == std::string::npos) throw std::logic_error("web/view.html lacks " + key);
    if (page_template.find(key, at + key.size()) != std::string::npos) {
      throw std::logic_error("web/view.html has " + key + " twice");
    }
    places.emplace_back(at, k);
  }
  std::sort(places.begin(), places.end());
  std::string page;
  size_t copied = 0;
  for (const auto& [at, k] : places) {
    page.append(page_template, copied, at - copied);
    page += keys_and_values[k].second;
    copied = at + keys_and_values[k].first.size();
  }
  page.append(page_template, copied, std::string::npos);
  return page;
}

// The page's reading of the camera file's `fit` record (docs/camera-file.md): each field it
// shows, of the type it shows it as. Only the camera is checked when its file is read; the
// record is free text to that reader, and the page puts its values in HTML. A field of another
// type ("num_points": "<img onerror=...>" ran as script, "left_out": "none" stopped the page's
// script, before session 43) is left out with a note, so the page shows only what a fit writes.
using FieldCheck = std::function<bool(const json&)>;
using FieldChecks = std::vector<std::pair<std::string, FieldCheck>>;

bool IsNumber(const json& v) { return v.is_number(); }
bool IsText(const json& v) { return v.is_string(); }
bool IsBool(const json& v) { return v.is_boolean(); }

FieldCheck ArrayOf(FieldCheck element) {
  return [element](const json& v) { return v.is_array() && std::all_of(v.begin(), v.end(), element); };
}

// An object of any keys whose values pass `value`.
FieldCheck MapOf(FieldCheck value) {
  return [value](const json& v) { return v.is_object() && std::all_of(v.begin(), v.end(), value); };
}

// An object holding the keys `required`, each passing its check, and the keys `optional` absent or
// passing theirs.
FieldCheck Record(FieldChecks required, FieldChecks optional = {}) {
  return [required, optional](const json& v) {
    if (!v.is_object()) return false;
    for (const auto& [key, check] : required) {
      if (!v.contains(key) || !check(v[key])) return false;
    }
    for (const auto& [key, check] : optional) {
      if (v.contains(key) && !check(v[key])) return false;
    }
    return true;
  };
}

// The fields of `fit` the page shows (web/view.js, Report) that pass their check; a note in
// `notes` for each that does not.
json FitRecordForPage(const json& fit, json& notes) {
  const FieldChecks fields = {
      {"model", IsText},
      {"rms_px", IsNumber},
      {"median_px", IsNumber},
      {"max_px", IsNumber},
      {"num_points", IsNumber},
      {"outliers", ArrayOf(IsNumber)},
      {"outlier_method", IsText},
      {"linearity", Record({{"linear", IsBool}, {"level", IsNumber}},
                           {{"worst_deviation", IsNumber}, {"worst_direction", IsText}})},
      {"sigma", MapOf(IsNumber)},
      {"left_out", ArrayOf(Record({{"name", IsText}, {"why", IsText}}))},
      {"selection",
       Record({{"criterion", IsText},
               {"candidates", ArrayOf(Record({{"name", IsText}, {"verdict", IsText}},
                                             {{"rms_px", IsNumber}, {"criterion", IsNumber}}))}})},
  };
  json shown = json::object();
  for (const auto& [key, check] : fields) {
    if (!fit.contains(key)) continue;
    if (check(fit[key])) {
      shown[key] = fit[key];
    } else {
      notes.push_back(Concat("the camera file's fit.", key,
                             " is not as camproj fit writes it (docs/camera-file.md): not shown"));
    }
  }
  return shown;
}

}  // namespace

std::string ViewPageHtml(const Camera& camera, const std::string& camera_file_text,
                         const std::string& camera_name, const Correspondences* correspondences,
                         const ViewOptions& options, ViewStats* stats_out) {
  options.Check();
  camera.Check();
  ViewStats stats;
  json fit = nullptr;
  {
    // The camera file was read and checked by the caller; here only its `fit` record is wanted.
    const json document = json::parse(camera_file_text, nullptr, false);
    if (document.is_object() && document.contains("fit") && document["fit"].is_object()) {
      fit = document["fit"];
    }
  }
  const PageFrame in_page{Inverse(camera.cam_from_world).translation};
  json data = SceneJson(camera, in_page, OutlierIndicesFromJsonText(camera_file_text, camera_name),
                        correspondences, stats);
  const json fit_shown = fit.is_null() ? json(nullptr) : FitRecordForPage(fit, data["notes"]);
  data["fit"] = fit_shown;
  data["camera_name"] = camera_name;
  data["image"] = options.image_path.empty() ? json(nullptr) : ImageJson(options.image_path, camera);
  data["mesh"] = options.mesh_path.empty() ? json(nullptr) : MeshJson(options.mesh_path, in_page, stats);
  const internal::ViewAssets& assets = internal::EmbeddedViewAssets();
  data["three_version"] = std::string(assets.three_version);

  const std::string title =
      options.title.empty() ? "camproj view: " + camera_name : options.title;
  const std::string page =
      FillTemplate(std::string(assets.page_template),
                   {{"@CAMPROJ_TITLE@", internal::MarkupEscape(title)},
                    {"@CAMPROJ_DATA@", ScriptSafeJson(data)},
                    {"@CAMPROJ_THREE_CORE@", Base64(assets.three_core)},
                    {"@CAMPROJ_THREE_MODULE@", Base64(assets.three_module)},
                    {"@CAMPROJ_ORBIT_CONTROLS@", Base64(assets.orbit_controls)},
                    {"@CAMPROJ_PAGE_SCRIPT@", Base64(assets.page_script)}});
  stats.page_bytes = page.size();
  if (stats_out) *stats_out = stats;
  return page;
}

ViewStats WriteViewPage(const Camera& camera, const std::string& camera_file_text,
                        const std::string& camera_name, const Correspondences* correspondences,
                        const ViewOptions& options, const std::string& output_path) {
  ViewStats stats;
  const std::string page =
      ViewPageHtml(camera, camera_file_text, camera_name, correspondences, options, &stats);
  WriteFileAtomically(output_path, page);
  return stats;
}

}  // namespace camproj
