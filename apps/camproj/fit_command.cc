// camproj fit: correspondences -> camera file and a summary.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "camproj/camera_file.h"
#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/fit.h"
#include "camproj/fit_plots.h"
#include "camproj/fit_report.h"
#include "camproj/fit_request.h"
#include "camproj/model_select.h"
#include "camproj/number_text.h"
#include "camproj/points_file.h"
#include "camproj/terminal_text.h"
#include "camproj/world_origin.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct FitArgs {
  std::vector<std::string> points_paths;
  int jobs = 0;
  std::string image_size;
  std::string output_path;
  bool json = false;
  bool trace = false;
  std::string report_path;
  // The fit's options (fit_request.h), bound to the command line directly; the three below are
  // what the command line reads or parses into them.
  FitArguments fit;
  std::string principal_point;
  std::string intrinsics_path;
  std::string object_points_path;
  std::string bounds;  // --bounds X0,Y0,Z0,X1,Y1,Z1
  std::string bounds_mesh_path;
  std::string origin;  // --origin auto|X,Y,Z
};
const std::vector<std::string> kParameterNames = {"focal", "aspect", "principal-point",
                                                  "skew",  "k1",     "k2"};

// The memory the default fit holds per point on top of the points as read (bytes): its
// bytes per point at 100 000 and 400 000 points in docs/bench/memory.md (`bench --memory`: 189
// and 171), rounded up. Below 100 000 points the fixed part dominates, but then it is a few MB.
constexpr double kFitBytesPerPoint = 200.0;

// A field of a /proc file in kB ("MemAvailable" of /proc/meminfo, "VmSize" of
// /proc/self/status); nullopt where the file or the field is missing.
std::optional<double> ProcKb(const char* path, const std::string& field) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, field.size() + 1, field + ":") == 0) {
      return std::atof(line.c_str() + field.size() + 1);
    }
  }
  return std::nullopt;
}

// The memory this process can still take (bytes): the smaller of the machine's available
// memory and, under an address-space limit (ulimit -v), the limit minus what is mapped now;
// nullopt where neither is known. Linux overcommits: without this check a fit too large for the
// machine ends by the OOM killer, not by a message.
std::optional<double> AvailableBytes() {
  std::optional<double> available;
  if (const std::optional<double> kb = ProcKb("/proc/meminfo", "MemAvailable")) {
    available = 1024.0 * *kb;
  }
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    if (const std::optional<double> kb = ProcKb("/proc/self/status", "VmSize")) {
      const double left = static_cast<double>(limit.rlim_cur) - 1024.0 * *kb;
      available = available ? std::min(*available, left) : left;
    }
  }
  return available;
}

// Refuses, naming the file, a fit that needs more memory than this process can still take.
void RequireMemoryToFit(const std::string& path, size_t num_points) {
  const double needed = kFitBytesPerPoint * static_cast<double>(num_points);
  const std::optional<double> available = AvailableBytes();
  if (!available || needed <= *available) return;
  char text[256];
  std::snprintf(text, sizeof text,
                "fitting its %zu points needs about %.0f MB (%.0f bytes a point, "
                "docs/reliability.md), more than the %.0f MB this process can still take (free "
                "memory, ulimit -v): fit fewer points",
                num_points, needed / 1e6, kFitBytesPerPoint, std::max(0.0, *available) / 1e6);
  throw InputError(path + ": " + text);
}

FitResult RunFit(const Correspondences& data, const ImageSize& size, const FitRequest& request) {
  return RunFitRequest(data.points_in_world, data.pixels, data.ids, size, request);
}

// A file's correspondences and their fit. Running out of memory (a file with more rows than the
// machine can hold or fit) is reported as bad input naming the file, not as "std::bad_alloc".
struct FileFit {
  Correspondences data;
  FitResult fit;
};
FileFit FitFile(const std::string& path, const ImageSize& size, const FitRequest& request) {
  FileFit result;
  try {
    result.data = ReadCorrespondencesFile(path);
    RequireMemoryToFit(path, result.data.pixels.size());
    result.fit = RunFit(result.data, size, request);
  } catch (const std::bad_alloc&) {
    const size_t rows = result.data.pixels.size();
    throw InputError(path + ": out of memory " +
                     (rows == 0 ? std::string("reading it")
                                : "fitting its " + std::to_string(rows) + " points") +
                     ": a fit needs about " + std::to_string(static_cast<int>(kFitBytesPerPoint)) +
                     " bytes a point on top of the points read (docs/reliability.md); fit "
                     "fewer points");
  }
  return result;
}

// The library's request (fit_request.h) for the parsed options; the files they name are read
// here, and a value the library refuses is a usage error.
FitRequest RequestFrom(const FitArgs& args, const ImageSize& size) {
  FitArguments arguments = args.fit;
  if (!args.principal_point.empty()) {
    const std::vector<double> c = ParseNumbers(args.principal_point, 2, "--principal-point");
    arguments.principal_point = Eigen::Vector2d(c[0], c[1]);
  }
  if (!args.intrinsics_path.empty()) {
    arguments.known_intrinsics =
        ReadIntrinsicsFile(args.intrinsics_path, &arguments.known_intrinsics_image_size);
    arguments.known_intrinsics_path = args.intrinsics_path;
  }
  if (!args.bounds.empty()) {
    const std::vector<double> b = ParseNumbers(args.bounds, 6, "--bounds");
    arguments.bounds_in_world = BoxInWorld{{b[0], b[1], b[2]}, {b[3], b[4], b[5]}};
  }
  if (!args.bounds.empty() && !args.bounds_mesh_path.empty()) {
    throw UsageError("give --bounds or --bounds-mesh, not both");  // before reading the mesh
  }
  if (!args.bounds_mesh_path.empty()) {
    arguments.mesh_vertices_in_world = ReadMeshVertices(args.bounds_mesh_path);
  }
  if (args.origin == "auto") {
    arguments.auto_world_origin = true;
  } else if (!args.origin.empty()) {
    const std::vector<double> o = ParseNumbers(args.origin, 3, "--origin (auto or X,Y,Z)");
    arguments.world_origin = Eigen::Vector3d(o[0], o[1], o[2]);
  }
  try {
    if (!args.object_points_path.empty()) {
      // Every other option is checked before the file is read (with one placeholder point:
      // a robust loss refuses object points whatever they are).
      arguments.object_points_in_world = {Eigen::Vector3d::Zero()};
      FitRequestFrom(arguments, size);
      CorrespondencesLimits limits;
      limits.read_pixels = false;
      arguments.object_points_in_world =
          ReadCorrespondencesFile(args.object_points_path, limits).points_in_world;
    }
    return FitRequestFrom(arguments, size);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

// The camera file of a fit: its look-at target at the fit's distance, and the `fit` record.
std::string CameraFileTextOf(const FitResult& fit, PixelOrigin pixel_origin) {
  return FitCameraFileText(fit, pixel_origin);
}

// One row of the batch summary.
struct BatchRow {
  std::string input;
  std::string output;         // the camera file written for it (when ok)
  std::string status = "ok";  // ok | refused | bad input
  std::string detail;         // model and RMS, or the reason
  std::string fix;            // a refusal's SceneError::fix (also at the end of detail)
  int exit_code = kExitOk;
};

// The camera file of each input in `folder`: its name with .json. Two inputs with the same name
// (a/cam.csv, b/cam.csv) would overwrite each other, and an output that is an input would destroy
// it (as would one that is the --intrinsics, --object-points or --bounds-mesh file, in
// `also_read`): both are
// refused here, before anything is fitted.
std::vector<std::string> BatchOutputs(const std::vector<std::string>& inputs, const std::string& folder,
                                      const std::vector<std::string>& also_read) {
  std::vector<std::string> read = inputs;
  read.insert(read.end(), also_read.begin(), also_read.end());
  std::vector<std::string> outputs;
  std::map<std::string, std::string> input_of;
  for (const std::string& input : inputs) {
    const std::string output =
        (std::filesystem::path(folder) / (std::filesystem::path(input).stem().string() + ".json")).string();
    const auto [it, added] = input_of.emplace(output, input);
    if (!added) {
      throw UsageError("inputs " + it->second + " and " + input + " would both write " + output +
                       ": give the files different names or fit them in separate runs");
    }
    RequireOutputIsNotAnInput(output, read);
    outputs.push_back(output);
  }
  return outputs;
}

// One JSON line of `camproj fit --json` in batch mode.
std::string JsonLine(const BatchRow& row) {
  nlohmann::json line = {{"file", row.input},
                         {"status", row.status},
                         {"exit_code", row.exit_code},
                         {"detail", row.detail}};
  if (!row.fix.empty()) line["fix"] = row.fix;
  line["camera_file"] = row.exit_code == kExitOk ? nlohmann::json(row.output) : nlohmann::json();
  // Invalid UTF-8 in a file name or message is replaced, not thrown.
  return line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Fits every input on `jobs` threads: one camera file per input in the -o folder, a progress
// line on a terminal, a summary table (--json: one JSON object per line, the totals on stderr);
// one bad file is reported and does not stop the others.
// Exit code: the worst of the inputs' (0 ok, 2 bad input, 3 refused).
int FitBatch(const std::vector<std::string>& inputs, const ImageSize& size,
             const FitRequest& request, const FitArgs& args) {
  if (args.output_path.empty()) throw UsageError("batch fitting needs -o OUTPUT_FOLDER");
  if (args.trace) throw UsageError("--trace is for a single input");
  const std::vector<std::string> outputs =
      BatchOutputs(inputs, args.output_path,
                   {args.intrinsics_path, args.object_points_path, args.bounds_mesh_path});
  std::filesystem::create_directories(args.output_path);
  const int jobs = args.jobs > 0 ? args.jobs
                                 : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::vector<BatchRow> rows(inputs.size());
  std::atomic<size_t> next{0};
  std::atomic<size_t> done{0};
  std::mutex progress_mutex;
  const bool terminal = isatty(fileno(stderr)) != 0;
  const auto begin = std::chrono::steady_clock::now();
  auto work = [&]() {
    for (size_t i = next++; i < inputs.size(); i = next++) {
      BatchRow& row = rows[i];
      row.input = inputs[i];
      row.output = outputs[i];
      try {
        const auto [data, fit] = FitFile(inputs[i], size, request);
        WriteFileAtomically(outputs[i], CameraFileTextOf(fit, request.options().pixel_origin));
        char detail[256];
        std::snprintf(detail, sizeof detail, "%s, rms %.3f px, %zu points", fit.model.c_str(),
                      fit.rms_px, data.pixels.size());
        row.detail = detail;
      } catch (const SceneError& e) {
        row.status = "refused";
        row.detail = e.what();
        row.fix = e.fix();
        row.exit_code = kExitScene;
      } catch (const std::exception& e) {
        row.status = "bad input";
        row.detail = e.what();
        row.exit_code = kExitBadInput;
      }
      const size_t finished = ++done;
      if (terminal) {
        const std::lock_guard<std::mutex> lock(progress_mutex);
        std::cerr << "\r[" << finished << "/" << inputs.size() << "] " << std::flush;
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < std::min<int>(jobs, static_cast<int>(inputs.size())); ++t) threads.emplace_back(work);
  for (std::thread& thread : threads) thread.join();
  if (terminal) std::cerr << "\r";
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  int exit_code = kExitOk;
  int ok = 0;
  if (!args.json) std::cout << "file\tstatus\tdetail\n";
  for (const BatchRow& row : rows) {
    if (args.json) {
      std::cout << JsonLine(row) << '\n';
    } else {
      std::cout << TerminalSafe(row.input + '\t' + row.status + '\t' + row.detail) << '\n';
    }
    exit_code = std::max(exit_code, row.exit_code);
    ok += row.exit_code == kExitOk ? 1 : 0;
  }
  char totals[256];
  std::snprintf(totals, sizeof totals, "%d of %zu fitted in %.3f s on %d threads (%.1f fits/s); cameras in ",
                ok, inputs.size(), seconds, std::min<int>(jobs, static_cast<int>(inputs.size())),
                inputs.size() / std::max(seconds, 1e-9));
  (args.json ? std::cerr : std::cout) << totals << TerminalSafe(args.output_path) << '\n';
  return exit_code;
}

// The options naming the inputs and outputs.
void AddInputOutputOptions(CLI::App* app, FitArgs* args) {
  app->add_option("POINTS", args->points_paths,
                  "correspondences CSV; several files or a folder of *.csv fit them all in "
                  "parallel (-o names the output folder)")->required();
  app->add_option("--jobs", args->jobs, "parallel fits in batch mode (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("--image-size", args->image_size, "image size WIDTHxHEIGHT in pixels")->required();
  app->add_option("-o,--output", args->output_path, "write the camera file here");
  app->add_flag("--json", args->json,
                "print the camera file to stdout instead of the summary; in batch mode one JSON "
                "object per input and line (file, status, exit_code, detail, camera_file)");
  app->add_flag("--trace", args->trace,
                "also print the per-iteration error against time (on stderr with --json)");
  app->add_option("--report", args->report_path,
                  "also write plots of the fit, drawn by camproj: .svg (residual per point, "
                  "residuals over the image, the models tried with their criterion) or .html "
                  "(the same with the summary)");
}

// The camera model: which intrinsics are free, or their values.
void AddModelOptions(CLI::App* app, FitArgs* args) {
  app->add_option("--model", args->fit.model,
                  "auto (default): the simplest model the data support; or the free intrinsics "
                  "joined by '+', e.g. focal+principal-point, focal+aspect+principal-point+k1; "
                  "pose: none (with --intrinsics or fixed values); orthographic[+aspect][+skew]: "
                  "a parallel projection (scale in px per world unit)");
  app->add_option("--criterion", args->fit.criterion,
                  "model selection criterion: bic (default) or aic")
      ->check(CLI::IsMember({"aic", "bic"}));
  app->add_option("--free", args->fit.free, "estimate these: focal,aspect,principal-point,skew,k1,k2")
      ->delimiter(',')->check(CLI::IsMember(kParameterNames));
  app->add_option("--fix", args->fit.fix, "hold these at their defaults (aspect 1, principal point at "
                                      "the image centre, skew 0, k 0)")
      ->delimiter(',')->check(CLI::IsMember(kParameterNames));
  app->add_option("--focal", args->fit.focal, "fix the focal length fx (px)")->check(PositiveFinite());
  app->add_option("--fovy", args->fit.fovy_deg, "fix the focal length by the vertical field of view (degrees)")
      ->check(PositiveFinite());
  app->add_option("--aspect", args->fit.aspect, "fix fy/fx")->check(PositiveFinite());
  app->add_option("--principal-point", args->principal_point, "fix cx,cy (px)");
  app->add_option("--skew", args->fit.skew, "fix the skew (px)")->check(FiniteNumber());
  app->add_option("--k1", args->fit.k1, "fix k1")->check(FiniteNumber());
  app->add_option("--k2", args->fit.k2, "fix k2")->check(FiniteNumber());
  app->add_option("--intrinsics,--shared-intrinsics", args->intrinsics_path,
                  "known intrinsics (a camera file, a calibration from `camproj calibrate`, or "
                  "{\"intrinsics\": {...}}): fit the pose only");
  app->add_option("--pixel-origin", args->fit.pixel_origin,
                  "center: (0,0) is the centre of the top-left pixel (OpenCV); corner: its corner "
                  "(COLMAP)")->check(CLI::IsMember({"center", "corner"}));
}

// The refinement, the outlier stage and the checks an answer must pass.
void AddRefinementOptions(CLI::App* app, FitArgs* args) {
  app->add_option("--loss", args->fit.loss, "none, huber:SCALE or cauchy:SCALE (px)");
  app->add_option("--refiner", args->fit.refiner,
                  "least-squares engine: lm (the project's own Levenberg-Marquardt, default) or "
                  "ceres (ceres::Solver on the same residuals); either ends with the same "
                  "Gauss-Newton polish, at the same optimum");
  app->add_option("--ransac", args->fit.ransac_px,
                  "find mis-clicked points by RANSAC at this inlier threshold in px (e.g. 4) "
                  "instead of the automatic outlier stage; they are left out and listed")
      ->check(PositiveFinite());
  app->add_flag("--keep-all", args->fit.keep_all,
                "keep every point: no automatic outlier stage (a scene with mis-clicks is then "
                "refused by the consistency check, naming the worst points)");
  app->add_option("--sigma", args->fit.sigma,
                  "pixel noise per axis (px): the model selection, the consistency check and the "
                  "uncertainties use it; default: a 1 px prior for clicked points, combined with "
                  "the residuals")->check(PositiveFinite());
  app->add_option("--max-uncertainty", args->fit.max_uncertainty,
                  "refuse a camera the points determine more loosely than this (px, 1 sigma over "
                  "the box the points span; default 5)")->check(PositiveFinite());
  app->add_option("--object-points", args->object_points_path,
                  "CSV with X,Y,Z of the object's other points (e.g. the model's vertices): the "
                  "camera must be determined to --max-uncertainty there too, where they are in "
                  "the image (u,v columns are ignored)");
}

// The GL view: near, far, world origin; and the iteration budget.
void AddViewOptions(CLI::App* app, FitArgs* args) {
  app->add_option("--near", args->fit.z_near, "near plane of the GL matrices (default: tight)")
      ->check(PositiveFinite());
  app->add_option("--far", args->fit.z_far, "far plane (default: tight)")->check(PositiveFinite());
  app->add_option("--bounds", args->bounds,
                  "X0,Y0,Z0,X1,Y1,Z1: near and far cover this world box (e.g. the whole model; "
                  "its 8 corners' depths + 10 %) instead of the fitted points only");
  app->add_option("--bounds-mesh", args->bounds_mesh_path,
                  "an OBJ or PLY file of the model: near and far cover its vertices' bounding "
                  "box, as --bounds, and the camera is judged at its vertices, as "
                  "--object-points (unless given)");
  app->add_option("--origin", args->origin,
                  "auto or X,Y,Z: record a world origin in the camera file, so that GL exports' "
                  "view matrix takes vertices relative to it (float32 precision for large, e.g. "
                  "UTM, coordinates; docs/exports.md); auto: the fitted points' centroid rounded "
                  "to a power of ten of their extent");
  app->add_option("--max-iterations", args->fit.max_iterations, "refinement iterations")
      ->check(CLI::NonNegativeNumber);
}

// The notes after the summary: near and far, the fitted points they clip, the region judged,
// the world origin or float32.
void PrintNotes(const FitRequest& request, const FitResult& fit, const Correspondences& data) {
  std::cout << "note: " << NearFarNote(request, fit);
  std::istringstream clipped(ClippedPointsNote(request, fit, data.points_in_world, data.ids));
  for (std::string line; std::getline(clipped, line);) {
    std::cout << "note: " << TerminalSafe(line) << '\n';
  }
  if (const std::string judged = JudgedRegionNote(request, fit); !judged.empty()) {
    std::cout << "note: " << judged;
  }
  if (fit.camera.world_origin) {
    const Eigen::Vector3d& o = *fit.camera.world_origin;
    std::ostringstream line;
    line << std::setprecision(17) << "note: world origin " << o.x() << ',' << o.y() << ','
         << o.z()
         << (request.auto_world_origin ? " (--origin auto: the fitted points' centroid, rounded)"
                                       : " (--origin)")
         << ": GL exports' view matrix takes point_in_world minus it\n";
    std::cout << line.str();
  } else if (const double error = Float32PixelError(fit.camera, std::nullopt, fit.camera.z_near);
             error > kFloat32ErrorWarningPx) {
    std::printf("note: the world coordinates are too large for float32: GL exports would draw "
                "points ~%s px off at the near plane; fit with --origin auto (docs/exports.md)\n",
                GeneralBound(error, 2).c_str());
  }
}

// One points file: fits it, writes the camera file and the report asked for, prints the summary
// (or the camera file with --json) and the trace (on stderr with --json: stdout stays one JSON
// document).
int FitOneFile(const std::string& input, const ImageSize& size, const FitRequest& request,
               const FitArgs& args) {
  const auto begin = std::chrono::steady_clock::now();
  RequireDistinctOptionOutputs({{"-o", args.output_path}, {"--report", args.report_path}});
  if (!args.output_path.empty()) {
    RequireOutputIsNotAnInput(args.output_path, {input, args.intrinsics_path,
                                                 args.object_points_path, args.bounds_mesh_path});
  }
  if (!args.report_path.empty()) {
    try {
      FitReportFormatOfPath(args.report_path);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--report: ") + e.what());
    }
    RequireOutputIsNotAnInput(args.report_path,
                              {input, args.intrinsics_path, args.object_points_path,
                               args.bounds_mesh_path, args.output_path});
  }
  const auto [data, fit] = FitFile(input, size, request);
  const std::string text = CameraFileTextOf(fit, request.options().pixel_origin);
  // The camera file and the report as one write: a report that cannot be written leaves no
  // camera file either.
  std::vector<OutputFile> outputs;
  if (!args.output_path.empty()) outputs.push_back({args.output_path, text, "-o"});
  if (!args.report_path.empty()) {
    std::vector<Eigen::Vector2d> observed = data.pixels;
    for (auto& p : observed) {
      p = ConvertPixelOrigin(p, request.options().pixel_origin, PixelOrigin::kCenter);
    }
    outputs.push_back({args.report_path,
                       FitReportFormatOfPath(args.report_path) == "svg"
                           ? FitReportSvg(fit, observed, data.ids)
                           : FitReportHtml(fit, observed, data.ids, FitSummaryText(fit, data.ids),
                                           "camproj fit " + input),
                       "--report"});
  }
  WriteFilesAtomically(outputs);
  if (args.json) {
    std::cout << text;
  } else {
    std::cout << TerminalSafe(FitSummaryText(fit, data.ids));
    PrintNotes(request, fit, data);
    if (!args.output_path.empty()) std::cout << "wrote " << TerminalSafe(args.output_path) << "\n";
    // The summary's time is the fit's; reading and writing the files add to it.
    const double wall_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin)
            .count();
    std::printf("wall time: %.3f ms (reading %zu points, fitting, writing)\n", wall_ms,
                data.pixels.size());
  }
  if (args.trace) (args.json ? std::cerr : std::cout) << FitTraceText(fit);
  return kExitOk;
}

}  // namespace

Command AddFitCommand(CLI::App& root) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* app = root.add_subcommand(
      "fit",
      "Fit a camera (or projector) to 2D-3D correspondences.\n\n"
      "POINTS.csv has a header naming X,Y,Z,u,v (any order, extra columns ignored, optional id,\n"
      "'#' comments). The model is chosen automatically (--model auto): from pose + focal length\n"
      "(square pixels, centred principal point) it frees principal point, aspect, skew, k1, k2\n"
      "one at a time while the criterion (BIC by default) says the data support them, and\n"
      "lists what it left out and why. --model focal+principal-point\n"
      "(any '+' list) forces a model; --free forces a parameter in, --fix (or a value: --focal,\n"
      "--aspect, ...) keeps it out.\n"
      "Points that disagree with the rest (mis-clicks) are found and left out, each named with\n"
      "its distance from the camera's prediction (--keep-all keeps every point). A camera is\n"
      "written only if its residuals are consistent with the pixel noise (--sigma; default: a\n"
      "1 px prior for clicked points); otherwise exit 3 names the worst points and what to do.\n"
      "It must also be determined to --max-uncertainty px (1 sigma, default 5) over the box the\n"
      "points span (and the --object-points), no model that fits about as well may put the\n"
      "scene further away than that, and no click may go unchecked by the others (one whose\n"
      "mis-click would not show); otherwise exit 3 says where points are missing. A refusal\n"
      "prints why (\"cannot fit:\") and, on a line of its own, what to do (\"to fix:\").\n"
      "Prints a summary (parameters +- 1 sigma, residuals, worst points, time); -o writes the\n"
      "camera file (docs/camera-file.md) atomically.\n\n"
      "Examples:\n"
      "  camproj fit points.csv --image-size 1920x1080 -o camera.json\n"
      "  camproj fit plane.csv --image-size 640x480 --model focal+k1\n"
      "  camproj fit points.csv --image-size 1920x1080 --model focal+aspect+principal-point --loss huber:2\n"
      "  camproj fit points.csv --image-size 1920x1080 --intrinsics known.json\n"
      "  camproj fit clicks.csv --image-size 1920x1080 --object-points model_vertices.csv");
  AddInputOutputOptions(app, args.get());
  AddModelOptions(app, args.get());
  AddRefinementOptions(app, args.get());
  AddViewOptions(app, args.get());
  return {app, [args]() {
            const ImageSize size = ParseImageSize(args->image_size, "--image-size");
            const FitRequest request = RequestFrom(*args, size);
            const std::vector<std::string> inputs = ExpandInputs(args->points_paths);
            if (inputs.size() > 1 || std::filesystem::is_directory(args->points_paths.front())) {
              if (!args->report_path.empty()) {
                throw UsageError("--report is for one points file (a batch writes one camera "
                                 "file per input; fit a file alone for its report)");
              }
              return FitBatch(inputs, size, request, *args);
            }
            return FitOneFile(inputs.front(), size, request, *args);
          }};
}

}  // namespace camproj::cli
