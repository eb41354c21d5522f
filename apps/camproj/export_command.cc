// camproj export: a camera file in another tool's terms.
#include <cctype>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "camproj/camera_file.h"
#include "camproj/depth_precision.h"
#include "camproj/errors.h"
#include "camproj/export.h"
#include "camproj/number_text.h"
#include "camproj/file_io.h"
#include "camproj/lens_gl.h"
#include "camproj/world_origin.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct ExportArgs {
  std::string camera_path;
  std::string view;  // a calibration file's view, by name
  std::string to = "gl";
  std::string depth = "no";
  bool reversed_z = false;
  bool infinite_far = false;
  double z_near = 0.0;
  double z_far = 0.0;
  bool row_major = false;
  std::string pixel_origin = "center";
  bool quiet = false;
  std::string output_path;
  int mesh_step_px = 0;
  std::string origin;  // auto | X,Y,Z | none; empty: the camera file's
};

// The lower-case extension of `path` (".tif"), or "" without one.
std::string ExtensionOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string extension = path.substr(dot);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

// The camera to export: read (a camera file, or one view of a calibration) with --near, --far,
// --infinite-far and --origin applied.
Camera CameraToExport(const ExportArgs& args) {
  Camera camera = args.view.empty() ? ReadCameraFile(args.camera_path)
                                     : ReadCalibrationView(args.camera_path, args.view);
  if (args.z_near > 0.0) camera.z_near = args.z_near;
  if (args.z_far > 0.0) camera.z_far = args.z_far;
  if (args.infinite_far) {
    if (args.z_far > 0.0) throw UsageError("give --far or --infinite-far, not both");
    camera.z_far = kInfinity;
  }
  if (!(camera.z_far > camera.z_near)) {
    throw UsageError("far must be greater than near");
  }
  if (args.origin == "none") {
    camera.world_origin.reset();
  } else if (args.origin == "auto") {
    camera.world_origin = AutoOriginOfCamera(camera);
  } else if (!args.origin.empty()) {
    const std::vector<double> o = ParseNumbers(args.origin, 3, "--origin (auto, none or X,Y,Z)");
    camera.world_origin = Eigen::Vector3d(o[0], o[1], o[2]);
    bool finite = false;
    try {
      finite = GlEyeFromOriginWorld(camera.cam_from_world, *camera.world_origin).allFinite();
    } catch (const std::invalid_argument&) {
    }
    if (!finite) {
      throw UsageError("--origin: " + args.origin +
                       " is too far from the camera: the view matrix relative to it "
                       "overflows a double");
    }
  }
  return camera;
}

// An stmap's output must be an image file; no output may be the input.
void CheckOutput(const ExportArgs& args, bool stmap) {
  if (stmap) {
    if (args.output_path.empty()) {
      throw UsageError("--to " + args.to + " writes an image file: give -o MAP.tif, "
                       "MAP.tiff or MAP.exr");
    }
    const std::string extension = ExtensionOf(args.output_path);
    if (extension != ".tif" && extension != ".tiff" && extension != ".exr") {
      throw UsageError("--to " + args.to + ": the output " + args.output_path +
                       " must end in .tif, .tiff or .exr (32-bit float RGBA)");
    }
  }
  if (!args.output_path.empty()) {
    RequireOutputIsNotAnInput(args.output_path, {args.camera_path});
  }
}

// --to stmap or undistort-stmap: the map to -o, the render target's size and matrices to stdout.
void ExportStMap(const Camera& camera, const ExportArgs& args, const ExportOptions& options) {
  const LensMapDirection direction =
      args.to == "stmap" ? LensMapDirection::kDistort : LensMapDirection::kUndistort;
  std::string text;
  std::string bytes;
  try {
    text = LensRenderTargetText(camera, direction, options.depth);
    bytes = EncodeStMap(LensStMap(camera, direction), ExtensionOf(args.output_path));
  } catch (const std::invalid_argument& e) {
    throw InputError(args.camera_path + ": cannot export as " + args.to + ": " + e.what());
  }
  WriteFileAtomically(args.output_path, bytes);
  std::cout << text;
}

// Depth-precision advice (docs/exports.md) on stderr, so stdout stays the export.
void PrintDepthAdvice(const Camera& camera, ExportFormat format, const ExportOptions& options,
                      bool quiet) {
  if (camera.projection == Projection::kOrthographic && !quiet) {
    // Orthographic depth is linear: the same step everywhere.
    std::cerr << "camproj: note: orthographic depth is linear in distance: the 24-bit "
                 "step is (far - near) / 2^24 = "
              << (camera.z_far - camera.z_near) / 16777216.0 << " world units\n";
  } else {
    const DepthAdvice advice = AdviseDepth(
        camera.z_near, camera.z_far, options.depth,
        format == ExportFormat::kThree ? DepthAdviceTarget::kThreeJs
                                       : DepthAdviceTarget::kOpenGl);
    for (const std::string& warning : advice.warnings) {
      std::cerr << "camproj: warning: " << warning << '\n';
    }
    if (!quiet) {
      std::istringstream table(advice.table + advice.advice);
      for (std::string line; std::getline(table, line);) {
        std::cerr << "camproj: note: " << line << '\n';
      }
    }
  }
}

// Float32 precision of the vertices and the view matrix (world_origin.h): the error expected at
// the near plane, where it is largest, with and without the world origin; a warning when it is
// above kFloat32ErrorWarningPx without one.
void PrintFloat32Precision(const Camera& camera, bool quiet) {
  const double without = Float32PixelError(camera, std::nullopt, camera.z_near);
  const std::optional<Eigen::Vector3d> origin =
      camera.world_origin ? camera.world_origin : AutoOriginOfCamera(camera);
  const double with = Float32PixelError(camera, origin, camera.z_near);
  char line[512];
  std::snprintf(line, sizeof line,
                "float32 vertices and view matrix: expected error at the near plane "
                "(depth %.6g) %s px without a world origin, %s px with %s "
                "%.17g,%.17g,%.17g",
                camera.z_near, GeneralBound(without, 2).c_str(), GeneralBound(with, 2).c_str(),
                camera.world_origin ? "the world origin" : "--origin auto =",
                origin->x(), origin->y(), origin->z());
  if (!camera.world_origin && without > kFloat32ErrorWarningPx) {
    std::cerr << "camproj: warning: " << line
              << ": the coordinates are too large for float32; export with --origin "
                 "auto (or fit with --origin auto) and give vertices relative to it "
                 "(docs/exports.md)\n";
  } else if (!quiet) {
    std::cerr << "camproj: note: " << line << '\n';
  }
}

// Warns that a pinhole-only export (`to`) drops the lens: the matrix is not this camera.
void WarnPinholeOnly(const Camera& camera, const std::string& to) {
  const Intrinsics& k = camera.intrinsics;
  char line[768];
  std::snprintf(line, sizeof line,
                "camproj: warning: k1 = %.6g, k2 = %.6g%s: the %s export's projection "
                "matrix is the pinhole part only and puts points up to %.3g px (worst "
                "image corner) from where the lens images them; %s; opencv-yaml, "
                "colmap and json keep the lens (docs/exports.md)\n",
                k.k1, k.k2,
                k.HasBeyondTwoRadial()
                    ? (", p1 = " + ShortestDouble(k.p1) + ", p2 = " +
                       ShortestDouble(k.p2) + ", k3 = " + ShortestDouble(k.k3)).c_str()
                    : "",
                to.c_str(), PinholeErrorAtWorstCornerPx(camera),
                k.HasBeyondTwoRadial()
                    ? "the GL lens exports (glsl, stmap, distortion-mesh) render k1, "
                      "k2 only"
                    : "to render the lens export glsl (per vertex), stmap or "
                      "distortion-mesh (post-process warp)");
  std::cerr << line;
}

// The export asked for, to -o or stdout, with its notes and warnings on stderr.
int RunExport(const ExportArgs& args) {
  const Camera camera = CameraToExport(args);
  const bool stmap = args.to == "stmap" || args.to == "undistort-stmap";
  CheckOutput(args, stmap);
  ExportOptions options;
  options.mesh_step_px = args.mesh_step_px;
  options.depth.clip_depth = ClipDepthFromString(args.depth);
  options.depth.reversed_z = args.reversed_z;
  options.row_major = args.row_major;
  options.pixel_origin = PixelOriginFromString(args.pixel_origin);
  if (stmap) {
    ExportStMap(camera, args, options);
    return kExitOk;
  }
  const ExportFormat format = ExportFormatFromString(args.to);
  const bool gl_like = format == ExportFormat::kGl || format == ExportFormat::kGlm ||
                       format == ExportFormat::kThree || format == ExportFormat::kGlsl;
  // The exports whose projection matrix drops k1, k2 (glsl renders them).
  const bool pinhole_only = format == ExportFormat::kGl || format == ExportFormat::kGlm ||
                            format == ExportFormat::kThree;
  if (gl_like) {
    PrintDepthAdvice(camera, format, options, args.quiet);
    PrintFloat32Precision(camera, args.quiet);
  }
  if (pinhole_only && camera.intrinsics.HasDistortion()) WarnPinholeOnly(camera, args.to);
  const bool obj =
      format == ExportFormat::kDistortionMesh && ExtensionOf(args.output_path) == ".obj";
  std::string text;
  try {
    text = obj ? LensDistortionMeshObj(camera, options.mesh_step_px, options.depth)
               : ExportCamera(camera, format, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.camera_path + ": cannot export as " + args.to + ": " + e.what());
  }
  if (args.output_path.empty()) {
    std::cout << text;
  } else {
    WriteFileAtomically(args.output_path, text);
  }
  return kExitOk;
}

}  // namespace

Command AddExportCommand(CLI::App& root) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* app = root.add_subcommand(
      "export",
      "Write a camera in another tool's terms (docs/exports.md).\n\n"
      "  gl           projection and view matrices, 16 numbers each (column-major)\n"
      "  glm          a C++ snippet building them as glm::dmat4\n"
      "  opencv-yaml  cv::FileStorage YAML: camera_matrix, distortion_coefficients, rvec, tvec\n"
      "  colmap       cameras.txt and images.txt lines (COLMAP's corner pixel convention)\n"
      "  three        JSON for a three.js PerspectiveCamera (projectionMatrix, matrixWorld)\n"
      "  json         the camera file rewritten, without its fit record\n"
      "  glsl         GLSL rendering the lens (k1, k2) per vertex: camproj_lens(), matrices\n"
      "  distortion-mesh  JSON (or -o MESH.obj: OBJ) mesh warping a pinhole render target onto\n"
      "               the image (--mesh-step)\n"
      "  stmap        -o MAP.tif|.exr: Nuke STMap (32-bit float) warping the pinhole render\n"
      "               target onto the image; stdout: the render target's size and matrices\n"
      "  undistort-stmap  -o MAP.tif|.exr: STMap warping the plate onto the render target\n\n"
      "Examples:\n"
      "  camproj export camera.json --to gl --depth zo --reversed-z\n"
      "  camproj export camera.json --to stmap -o lens.tif > render_target.txt\n"
      "  camproj export camera.json --to opencv-yaml > camera.yaml\n"
      "  camproj export calib.json --view left03 --to gl   # one view of a calibration");
  app->add_option("CAMERA", args->camera_path, "camera file (docs/camera-file.md)")->required();
  app->add_option("--view", args->view,
                  "CAMERA is a calibration file (camproj calibrate): export this view's camera");
  app->add_option("--to", args->to, "format")
      ->check(CLI::IsMember({"gl", "glm", "opencv-yaml", "colmap", "three", "json", "glsl",
                             "distortion-mesh", "stmap", "undistort-stmap"}));
  app->add_option("--depth", args->depth, "clip depth: no = [-1,1] (GL default), zo = [0,1]")
      ->check(CLI::IsMember({"no", "zo"}));
  app->add_flag("--reversed-z", args->reversed_z, "near maps to 1, far to 0 (zo) or -1 (no)");
  app->add_flag("--infinite-far", args->infinite_far, "far plane at infinity");
  app->add_option("--near", args->z_near, "override the near plane")->check(PositiveFinite());
  app->add_option("--far", args->z_far, "override the far plane")->check(PositiveFinite());
  app->add_flag("--row-major", args->row_major, "gl: print rows instead of column-major order");
  app->add_option("--pixel-origin", args->pixel_origin, "json: convention of cx, cy written")
      ->check(CLI::IsMember({"center", "corner"}));
  app->add_option("-o,--output", args->output_path,
                  "write the export here (atomically); required for stmap and undistort-stmap, "
                  "whose extension (.tif, .tiff, .exr) picks the file type");
  app->add_option("--mesh-step", args->mesh_step_px,
                  "distortion-mesh: grid step in image px (default: the largest power of 2 up "
                  "to 64 whose interpolation error is <= 0.01 px)")
      ->check(CLI::Range(1, 1 << 20));
  app->add_option("--origin", args->origin,
                  "gl, glm, three, json: the world origin vertices are given relative to (the "
                  "view matrix becomes gl_eye_from_origin_world): X,Y,Z; auto = the camera centre "
                  "rounded to a power of ten not above near; none = world coordinates as they "
                  "are. Default: the camera file's world_origin");
  app->add_flag("--quiet", args->quiet,
                "gl, glm, glsl, three: no depth-precision notes on stderr (warnings still "
                "printed)");
  return {app, [args]() { return RunExport(*args); }};
}

}  // namespace camproj::cli
