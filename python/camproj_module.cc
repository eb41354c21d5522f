// The `camproj` Python module: a thin pybind11 layer over the library's public API
// (lib/include/camproj/). No geometry here: every number comes from a library call; this file
// converts numpy arrays, strings and exceptions. Conventions: docs/conventions.md; the Python
// API, with units, is in camproj.pyi.
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "camproj/camera.h"
#include "camproj/camera_file.h"
#include "camproj/conventions.h"
#include "camproj/errors.h"
#include "camproj/export.h"
#include "camproj/file_io.h"
#include "camproj/fit.h"
#include "camproj/fit_report.h"
#include "camproj/fit_request.h"
#include "camproj/frustum.h"
#include "camproj/gl.h"
#include "camproj/library_logging.h"
#include "camproj/look_at.h"
#include "camproj/points_file.h"
#include "camproj/pose.h"

namespace py = pybind11;
using namespace camproj;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A Camera, and when it comes from fit(), the fit and the points' ids. `target_distance` places
// the look-at target (the fit's: the points' median depth).
struct PyCamera {
  Camera camera;
  double target_distance = 1.0;
  std::shared_ptr<const FitResult> fit;
  std::vector<std::string> ids;
  PixelOrigin input_origin = PixelOrigin::kCenter;  // of the fitted pixels (the camera file's)
};

// (N, columns) float64 -> N vectors; ValueError naming `name` and the shape otherwise.
template <int kColumns>
std::vector<Eigen::Matrix<double, kColumns, 1>> Rows(const Array& array, const char* name) {
  if (array.ndim() != 2 || array.shape(1) != kColumns) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < array.ndim(); ++i) {
      shape += (i ? ", " : "") + std::to_string(array.shape(i));
    }
    if (array.ndim() == 1) shape += ",";
    throw std::invalid_argument(std::string(name) + ": expected an (N, " + std::to_string(kColumns) +
                                ") array, got shape " + shape + ")");
  }
  std::vector<Eigen::Matrix<double, kColumns, 1>> rows(array.shape(0));
  const double* data = array.data();
  for (size_t i = 0; i < rows.size(); ++i) {
    for (int j = 0; j < kColumns; ++j) rows[i][j] = data[i * kColumns + j];
  }
  return rows;
}

template <int kColumns>
py::array_t<double> ToArray(const std::vector<Eigen::Matrix<double, kColumns, 1>>& rows) {
  py::array_t<double> array({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(kColumns)});
  double* data = array.mutable_data();
  for (size_t i = 0; i < rows.size(); ++i) {
    for (int j = 0; j < kColumns; ++j) data[i * kColumns + j] = rows[i][j];
  }
  return array;
}

ImageSize SizeOf(const std::pair<int, int>& size) {
  const ImageSize image_size{size.first, size.second};
  image_size.Check();
  return image_size;
}

GlDepth DepthOf(const std::string& depth, bool reversed_z) {
  return GlDepth{ClipDepthFromString(depth), reversed_z};
}

Rigid3 PoseOf(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Rigid3 pose{R, t};
  pose.Check();
  return pose;
}

CameraViews ViewsOf(const PyCamera& c) { return ViewsOfCamera(c.camera, c.target_distance); }

// fit()'s keyword arguments -> the command line's FitArguments (fit_request.h).
FitArguments ArgumentsOf(const py::kwargs& kwargs) {
  FitArguments a;
  for (const auto& [key_handle, value] : kwargs) {
    const std::string key = py::str(key_handle);
    if (value.is_none()) continue;
    if (key == "model") a.model = value.cast<std::string>();
    else if (key == "criterion") a.criterion = value.cast<std::string>();
    else if (key == "free") a.free = value.cast<std::vector<std::string>>();
    else if (key == "fix") a.fix = value.cast<std::vector<std::string>>();
    else if (key == "focal") a.focal = value.cast<double>();
    else if (key == "fovy_deg") a.fovy_deg = value.cast<double>();
    else if (key == "aspect") a.aspect = value.cast<double>();
    else if (key == "principal_point") a.principal_point = value.cast<Eigen::Vector2d>();
    else if (key == "skew") a.skew = value.cast<double>();
    else if (key == "k1") a.k1 = value.cast<double>();
    else if (key == "k2") a.k2 = value.cast<double>();
    else if (key == "intrinsics") {
      a.known_intrinsics = py::isinstance<py::str>(value)
                               ? ReadIntrinsicsFile(value.cast<std::string>())
                               : value.cast<Intrinsics>();
    } else if (key == "pixel_origin") a.pixel_origin = value.cast<std::string>();
    else if (key == "loss") a.loss = value.cast<std::string>();
    else if (key == "refiner") a.refiner = value.cast<std::string>();
    else if (key == "keep_all") a.keep_all = value.cast<bool>();
    else if (key == "ransac_px") a.ransac_px = value.cast<double>();
    else if (key == "sigma") a.sigma = value.cast<double>();
    else if (key == "max_uncertainty") a.max_uncertainty = value.cast<double>();
    else if (key == "object_points_in_world") {
      a.object_points_in_world = Rows<3>(value.cast<Array>(), "object_points_in_world");
    } else if (key == "near") a.z_near = value.cast<double>();
    else if (key == "far") a.z_far = value.cast<double>();
    else if (key == "bounds") {
      const auto b = value.cast<std::vector<double>>();
      if (b.size() != 6) {
        throw std::invalid_argument("bounds: expected 6 numbers X0,Y0,Z0,X1,Y1,Z1, got " +
                                    std::to_string(b.size()));
      }
      a.bounds_in_world = BoxInWorld{{b[0], b[1], b[2]}, {b[3], b[4], b[5]}};
    }
    else if (key == "bounds_mesh") {
      a.mesh_vertices_in_world = py::isinstance<py::str>(value)
                                     ? ReadMeshVertices(value.cast<std::string>())
                                     : Rows<3>(value.cast<Array>(), "bounds_mesh");
      // An empty mesh file is refused by its reader; so is an empty array (not "no mesh").
      if (a.mesh_vertices_in_world.empty()) {
        throw std::invalid_argument("bounds_mesh: no vertices");
      }
    } else if (key == "origin") {
      if (py::isinstance<py::str>(value)) {
        if (value.cast<std::string>() != "auto") {
          throw std::invalid_argument("origin: expected \"auto\" or 3 numbers X, Y, Z, got \"" +
                                      value.cast<std::string>() + "\"");
        }
        a.auto_world_origin = true;
      } else {
        const auto o = value.cast<std::vector<double>>();
        if (o.size() != 3) {
          throw std::invalid_argument("origin: expected \"auto\" or 3 numbers X, Y, Z, got " +
                                      std::to_string(o.size()) + " numbers");
        }
        a.world_origin = Eigen::Vector3d(o[0], o[1], o[2]);
      }
    }
    else if (key == "max_iterations") a.max_iterations = value.cast<int>();
    else throw std::invalid_argument("fit: unknown option \"" + key + "\" (see help(camproj.fit))");
  }
  // The command line refuses non-positive values of these options before they reach the library.
  const std::pair<const char*, double> positive[] = {
      {"focal", a.focal}, {"fovy_deg", a.fovy_deg}, {"aspect", a.aspect}, {"ransac_px", a.ransac_px},
      {"sigma", a.sigma}, {"max_uncertainty", a.max_uncertainty}, {"near", a.z_near}, {"far", a.z_far}};
  for (const auto& [name, v] : positive) {
    if (kwargs.contains(name) && !kwargs[name].is_none() && !(v > 0.0)) {
      throw std::invalid_argument(std::string(name) + ": expected a positive number, got " + std::to_string(v));
    }
  }
  if (a.max_iterations < 0) throw std::invalid_argument("max_iterations: expected >= 0");
  return a;
}

PyCamera Fit(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector2d>& pixels,
             const std::vector<std::string>& ids, const ImageSize& size, const FitArguments& arguments) {
  const FitRequest request = FitRequestFrom(arguments, size);
  PyCamera result;
  {
    py::gil_scoped_release release;  // fits in threads of one process run in parallel
    auto fit = std::make_shared<FitResult>(RunFitRequest(points, pixels, ids, size, request));
    result.fit = fit;
  }
  result.camera = result.fit->camera;
  result.target_distance = (result.fit->views.look_at.target - result.fit->views.look_at.eye).norm();
  result.ids = ids;
  result.input_origin = request.options().pixel_origin;
  return result;
}

std::vector<std::string> IdsOf(const py::object& ids, size_t count) {
  if (ids.is_none()) return {};
  auto list = ids.cast<std::vector<std::string>>();
  if (list.size() != count) {
    throw std::invalid_argument("ids: expected one per point (" + std::to_string(count) + "), got " +
                                std::to_string(list.size()));
  }
  return list;
}

const char* ReasonName(SceneError::Reason reason) {
  switch (reason) {
    case SceneError::Reason::kTooFewPoints: return "TooFewPointsError";
    case SceneError::Reason::kCollinearPoints: return "CollinearPointsError";
    case SceneError::Reason::kPlanarUnderdetermined: return "PlanarUnderdeterminedError";
    case SceneError::Reason::kNonFiniteInput: return "NonFiniteInputError";
    case SceneError::Reason::kPointsBehindCamera: return "PointsBehindCameraError";
    case SceneError::Reason::kMirroredWorld: return "MirroredWorldError";
    case SceneError::Reason::kDegenerate: return "DegenerateError";
    case SceneError::Reason::kContaminated: return "ContaminatedError";
    case SceneError::Reason::kInconsistent: return "InconsistentError";
    case SceneError::Reason::kAmbiguous: return "AmbiguousError";
    case SceneError::Reason::kNumerical: return "NumericalError";
  }
  return "SceneError";
}

}  // namespace

PYBIND11_MODULE(camproj, m) {
  m.doc() = "camproj: fit OpenGL/OpenCV cameras to 2D-3D correspondences and convert between "
            "intrinsics, pose, look-at, frustum and GL matrices. Conventions: docs/conventions.md.";
  SetLibraryLogging(false);  // as the command line without --verbose: no Ceres/OpenCV log lines

  // Exceptions: SceneError (a refusal, one subclass per SceneError::Reason), InputError (a bad
  // file, a ValueError); std::invalid_argument -> ValueError (pybind11's own translation).
  static py::exception<SceneError> scene_error(m, "SceneError", PyExc_RuntimeError);
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  // Leaked on purpose: Python objects must not be released after the interpreter is finalized.
  static auto& subclasses = *new std::map<SceneError::Reason, py::object>;
  for (int r = 0; r <= static_cast<int>(SceneError::Reason::kNumerical); ++r) {
    const auto reason = static_cast<SceneError::Reason>(r);
    py::object cls = py::reinterpret_steal<py::object>(PyErr_NewException(
        (std::string("camproj.") + ReasonName(reason)).c_str(), scene_error.ptr(), nullptr));
    m.attr(ReasonName(reason)) = cls;
    subclasses[reason] = cls;
  }
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SceneError& e) {
      // The exception carries the refusal's parts too: .why and .fix (SceneError::fix).
      const py::object& type = subclasses.at(e.reason());
      py::object error = type(e.what());
      error.attr("why") = e.why();
      error.attr("fix") = e.fix();
      PyErr_SetObject(type.ptr(), error.ptr());
    } catch (const InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    }
  });

  py::class_<Intrinsics>(m, "Intrinsics", "Pinhole intrinsics (px) with OpenCV's lens k1, k2, p1, "
                                          "p2, k3; cx, cy in OpenCV's pixel origin "
                                          "(docs/conventions.md).")
      .def(py::init([](double fx, double fy, double cx, double cy, double skew, double k1,
                       double k2, double p1, double p2, double k3) {
             Intrinsics k{fx, fy, cx, cy, skew, k1, k2, p1, p2, k3};
             k.Check();
             return k;
           }),
           py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"), py::arg("skew") = 0.0,
           py::arg("k1") = 0.0, py::arg("k2") = 0.0, py::arg("p1") = 0.0, py::arg("p2") = 0.0,
           py::arg("k3") = 0.0)
      .def_readonly("fx", &Intrinsics::fx)
      .def_readonly("fy", &Intrinsics::fy)
      .def_readonly("cx", &Intrinsics::cx)
      .def_readonly("cy", &Intrinsics::cy)
      .def_readonly("skew", &Intrinsics::skew)
      .def_readonly("k1", &Intrinsics::k1)
      .def_readonly("k2", &Intrinsics::k2)
      .def_readonly("p1", &Intrinsics::p1)
      .def_readonly("p2", &Intrinsics::p2)
      .def_readonly("k3", &Intrinsics::k3)
      .def_property_readonly("K", &Intrinsics::K)
      .def_static("from_K", &IntrinsicsFromK, py::arg("K"))
      .def("__repr__", [](const Intrinsics& k) {
        if (!k.HasBeyondTwoRadial()) {
          return py::str("Intrinsics(fx={}, fy={}, cx={}, cy={}, skew={}, k1={}, k2={})")
              .format(k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2);
        }
        return py::str("Intrinsics(fx={}, fy={}, cx={}, cy={}, skew={}, k1={}, k2={}, p1={}, "
                       "p2={}, k3={})")
            .format(k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2, k.p1, k.p2, k.k3);
      });

  py::class_<Frustum>(m, "Frustum", "glFrustum's near-plane window and depth range (gl_eye units).")
      .def(py::init([](double l, double r, double b, double t, double n, double f) {
             Frustum fr{l, r, b, t, n, f};
             fr.Check();
             return fr;
           }),
           py::arg("left"), py::arg("right"), py::arg("bottom"), py::arg("top"), py::arg("near"),
           py::arg("far"))
      .def_readonly("left", &Frustum::left)
      .def_readonly("right", &Frustum::right)
      .def_readonly("bottom", &Frustum::bottom)
      .def_readonly("top", &Frustum::top)
      .def_readonly("near", &Frustum::z_near)
      .def_readonly("far", &Frustum::z_far)
      .def("__repr__", [](const Frustum& f) {
        return py::str("Frustum(left={}, right={}, bottom={}, top={}, near={}, far={})")
            .format(f.left, f.right, f.bottom, f.top, f.z_near, f.z_far);
      });

  py::class_<Perspective>(m, "Perspective", "gluPerspective's fovy (degrees), aspect, near, far.")
      .def(py::init([](double fovy_deg, double aspect, double n, double f) {
             Perspective p{fovy_deg, aspect, n, f};
             p.Check();
             return p;
           }),
           py::arg("fovy_deg"), py::arg("aspect"), py::arg("near"), py::arg("far"))
      .def_readonly("fovy_deg", &Perspective::fovy_deg)
      .def_readonly("aspect", &Perspective::aspect)
      .def_readonly("near", &Perspective::z_near)
      .def_readonly("far", &Perspective::z_far)
      .def("__repr__", [](const Perspective& p) {
        return py::str("Perspective(fovy_deg={}, aspect={}, near={}, far={})")
            .format(p.fovy_deg, p.aspect, p.z_near, p.z_far);
      });

  py::class_<LeftOutPoint>(m, "LeftOutPoint")
      .def_readonly("index", &LeftOutPoint::index)
      .def_readonly("residual_px", &LeftOutPoint::residual_px)
      .def_readonly("rms_with_px", &LeftOutPoint::rms_with_px);

  py::class_<FitResult, std::shared_ptr<FitResult>>(m, "FitReport", "What the fit reports (fit.h's FitResult).")
      .def_readonly("rms_px", &FitResult::rms_px)
      .def_readonly("median_px", &FitResult::median_px)
      .def_readonly("max_px", &FitResult::max_px)
      .def_readonly("model", &FitResult::model)
      .def_readonly("criterion", &FitResult::criterion)
      .def_readonly("start_method", &FitResult::start_method)
      .def_readonly("planar", &FitResult::planar)
      .def_readonly("free_parameters", &FitResult::free_parameters)
      .def_readonly("outliers", &FitResult::outliers)
      .def_readonly("outlier_method", &FitResult::outlier_method)
      .def_readonly("left_out", &FitResult::left_out)
      .def_readonly("jacobian_condition", &FitResult::jacobian_condition)
      .def_readonly("iterations", &FitResult::iterations)
      .def_readonly("time_ms", &FitResult::time_ms)
      .def_readonly("pixel_sigma", &FitResult::pixel_sigma)
      .def_readonly("pixel_sigma_estimated", &FitResult::pixel_sigma_estimated)
      .def_property_readonly("residuals_px", [](const FitResult& f) { return ToArray<2>(f.residuals_px); })
      .def_property_readonly("covariance", [](const FitResult& f) -> py::object {
        if (!f.covariance_available) return py::none();
        return py::cast(f.covariance);
      })
      .def_property_readonly("sigmas", [](const FitResult& f) {
        py::dict d;
        for (const ParameterSigma& s : f.sigmas) d[py::str(s.name)] = py::make_tuple(s.value, s.sigma, s.unit);
        return d;
      })
      .def_property_readonly("left_out_parameters", [](const FitResult& f) { return FitRecordOf(f).left_out; })
      .def_property_readonly("fixed_parameters", [](const FitResult& f) { return FitRecordOf(f).fixed; })
      .def_property_readonly("consistency", [](const FitResult& f) { return f.consistency.summary; })
      .def_property_readonly("determination", [](const FitResult& f) { return f.determination.summary; })
      .def_property_readonly("reliability", [](const FitResult& f) -> py::object {
        if (!f.reliability.checked) return py::none();
        py::dict d;
        d["point"] = f.reliability.point;
        d["redundancy"] = f.reliability.redundancy;
        d["direction"] = py::make_tuple(f.reliability.direction.x(), f.reliability.direction.y());
        d["summary"] = f.reliability.summary;
        return d;
      })
      .def_property_readonly("linearity", [](const FitResult& f) -> py::object {
        if (!f.linearity.checked) return py::none();
        py::dict d;
        d["linear"] = f.linearity.linear;
        d["level"] = f.linearity.level;
        d["worst_deviation"] = f.linearity.worst_deviation;
        d["bound"] = f.linearity.bound;
        d["worst_direction"] = f.linearity.worst_direction;
        d["summary"] = LinearityText(f.linearity);
        return d;
      });

  py::class_<PyCamera>(m, "Camera", "A camera: image size, intrinsics (cx, cy in OpenCV's pixel "
                                    "origin), cam_from_world pose, GL depth range.")
      .def(py::init([](std::pair<int, int> size, const Eigen::Matrix3d& K, const Eigen::Matrix3d& R,
                       const Eigen::Vector3d& t, double k1, double k2, double z_near, double z_far,
                       double target_distance) {
             PyCamera c;
             c.camera.image_size = SizeOf(size);
             c.camera.intrinsics = IntrinsicsFromK(K);
             c.camera.intrinsics.k1 = k1;
             c.camera.intrinsics.k2 = k2;
             c.camera.cam_from_world = Rigid3{R, t};
             c.camera.z_near = z_near;
             c.camera.z_far = z_far;
             c.camera.Check();
             c.target_distance = target_distance;
             return c;
           }),
           py::arg("image_size"), py::arg("K"), py::arg("R"), py::arg("t"), py::arg("k1") = 0.0,
           py::arg("k2") = 0.0, py::arg("near") = 0.1, py::arg("far") = 100.0,
           py::arg("target_distance") = 1.0)
      .def_static("from_look_at",
                  [](std::pair<int, int> size, const Eigen::Matrix3d& K, const Eigen::Vector3d& eye,
                     const Eigen::Vector3d& target, const Eigen::Vector3d& up, double z_near,
                     double z_far) {
                    PyCamera c;
                    c.camera.image_size = SizeOf(size);
                    c.camera.intrinsics = IntrinsicsFromK(K);
                    c.camera.cam_from_world = CamFromWorldFromLookAt(LookAt{eye, target, up});
                    c.camera.z_near = z_near;
                    c.camera.z_far = z_far;
                    c.camera.Check();
                    c.target_distance = (target - eye).norm();
                    return c;
                  },
                  py::arg("image_size"), py::arg("K"), py::arg("eye"), py::arg("target"),
                  py::arg("up"), py::arg("near") = 0.1, py::arg("far") = 100.0)
      .def_property_readonly("image_size", [](const PyCamera& c) {
        return py::make_tuple(c.camera.image_size.width, c.camera.image_size.height);
      })
      .def_property_readonly("intrinsics", [](const PyCamera& c) { return c.camera.intrinsics; })
      .def_property_readonly("K", [](const PyCamera& c) { return c.camera.intrinsics.K(); })
      // R and t are views into the camera (no copy; read-only); they keep it alive.
      .def_property_readonly(
          "R", [](const PyCamera& c) -> const Eigen::Matrix3d& { return c.camera.cam_from_world.rotation; },
          py::return_value_policy::reference_internal, "cam_from_world rotation (3x3), a read-only view")
      .def_property_readonly(
          "t", [](const PyCamera& c) -> const Eigen::Vector3d& { return c.camera.cam_from_world.translation; },
          py::return_value_policy::reference_internal, "cam_from_world translation (3,), world units, a read-only view")
      .def_property_readonly("near", [](const PyCamera& c) { return c.camera.z_near; })
      .def_property_readonly("far", [](const PyCamera& c) { return c.camera.z_far; })
      .def_property_readonly("world_origin", [](const PyCamera& c) { return c.camera.world_origin; },
                             "The world origin GL exports' view matrix is relative to (3,), or None "
                             "(docs/conventions.md, section 11).")
      .def_property_readonly("projection", [](const PyCamera& c) {
        return c.camera.projection == Projection::kPerspective ? "perspective" : "orthographic";
      })
      .def_property_readonly("eye", [](const PyCamera& c) { return ViewsOf(c).look_at.eye; })
      .def_property_readonly("target", [](const PyCamera& c) { return ViewsOf(c).look_at.target; })
      .def_property_readonly("up", [](const PyCamera& c) { return ViewsOf(c).look_at.up; })
      .def_property_readonly("frustum", [](const PyCamera& c) { return ViewsOf(c).frustum; })
      .def_property_readonly("perspective", [](const PyCamera& c) { return ViewsOf(c).perspective; })
      .def_property_readonly("report", [](const PyCamera& c) -> py::object {
        if (!c.fit) return py::none();
        return py::cast(std::const_pointer_cast<FitResult>(c.fit));
      })
      .def_property_readonly("ids", [](const PyCamera& c) { return c.ids; })
      .def_property_readonly("outlier_ids", [](const PyCamera& c) {
        std::vector<std::string> out;
        if (c.fit) {
          for (int i : c.fit->outliers) out.push_back(c.ids.empty() ? std::to_string(i + 1) : c.ids[i]);
        }
        return out;
      })
      .def("gl_projection",
           [](const PyCamera& c, std::optional<double> z_near, std::optional<double> z_far,
              const std::string& depth, bool reversed_z) {
             const double n = z_near.value_or(c.camera.z_near);
             const double f = z_far.value_or(c.camera.z_far);
             const GlDepth d = DepthOf(depth, reversed_z);
             const Intrinsics k = c.camera.intrinsics.Pinhole();
             return c.camera.projection == Projection::kPerspective
                        ? ClipFromGlEye(k, c.camera.image_size, n, f, d)
                        : ClipFromGlEyeOrthographic(k, c.camera.image_size, n, f, d);
           },
           "clip_from_gl_eye (4x4): the GL projection matrix of the pinhole part (k1, k2 dropped); near/far default to the camera's (far=math.inf: infinite), depth \"no\" ([-1, 1]) or \"zo\" ([0, 1]), reversed_z.",
           py::arg("near") = py::none(), py::arg("far") = py::none(), py::arg("depth") = "no",
           py::arg("reversed_z") = false)
      .def("gl_view", [](const PyCamera& c) { return GlEyeFromWorld(c.camera.cam_from_world); },
           "gl_eye_from_world (4x4): the GL view matrix (docs/conventions.md).")
      .def("project",
           [](const PyCamera& c, const Array& points) {
             const auto rows = Rows<3>(points, "points_in_world");
             std::vector<Eigen::Vector2d> pixels(rows.size());
             for (size_t i = 0; i < rows.size(); ++i) {
               pixels[i] = PixelFromWorld(c.camera, rows[i])
                               .value_or(Eigen::Vector2d::Constant(std::nan("")));
             }
             return ToArray<2>(pixels);
           },
           "Pixels (N, 2; OpenCV origin, px, distortion included) of points_in_world (N, 3); NaN rows for points not in front of the camera.",
           py::arg("points_in_world"))
      .def("summary", [](const PyCamera& c) {
        if (!c.fit) throw std::invalid_argument("summary: this camera was not fitted");
        return FitSummaryText(*c.fit, c.ids);
      })
      .def("to_json",
           [](const PyCamera& c, std::optional<std::string> origin) {
             const PixelOrigin o = origin ? PixelOriginFromString(*origin) : c.input_origin;
             if (c.fit) return FitCameraFileText(*c.fit, o);
             CameraFileOptions options;
             options.pixel_origin = o;
             options.target_distance = c.target_distance;
             return CameraToJsonText(c.camera, options);
           },
           "The camera file text (docs/camera-file.md); for a fitted camera what `camproj fit -o` writes.",
           py::arg("pixel_origin") = py::none())
      .def("export",
           [](const PyCamera& c, const std::string& format, const std::string& depth,
              bool reversed_z, bool row_major, const std::string& origin,
              std::optional<double> z_near, std::optional<double> z_far) {
             ExportOptions options;
             options.depth = DepthOf(depth, reversed_z);
             options.row_major = row_major;
             options.pixel_origin = PixelOriginFromString(origin);
             Camera camera = c.camera;  // `camproj export --near/--far`: another depth range
             camera.z_near = z_near.value_or(camera.z_near);
             camera.z_far = z_far.value_or(camera.z_far);
             return ExportCamera(camera, ExportFormatFromString(format), options);
           },
           "`camproj export --to FORMAT` as a string: format in EXPORT_FORMATS (docs/exports.md).",
           py::arg("format"), py::arg("depth") = "no", py::arg("reversed_z") = false,
           py::arg("row_major") = false, py::arg("pixel_origin") = "center",
           py::arg("near") = py::none(), py::arg("far") = py::none())
      .def("write",
           [](const PyCamera& c, const std::string& path, std::optional<std::string> origin) {
             const PixelOrigin o = origin ? PixelOriginFromString(*origin) : c.input_origin;
             CameraFileOptions options;
             options.pixel_origin = o;
             options.target_distance = c.target_distance;
             WriteFileAtomically(path, c.fit ? FitCameraFileText(*c.fit, o) : CameraToJsonText(c.camera, options));
           },
           "to_json() written atomically to path.",
           py::arg("path"), py::arg("pixel_origin") = py::none())
      .def("__repr__", [](const PyCamera& c) {
        const Intrinsics& k = c.camera.intrinsics;
        return py::str("<camproj.Camera {}x{} fx={} fy={} cx={} cy={}{}>")
            .format(c.camera.image_size.width, c.camera.image_size.height, k.fx, k.fy, k.cx, k.cy,
                    c.fit ? " model=" + c.fit->model : std::string());
      });

  m.def("fit",
        [](const Array& points, const Array& pixels, std::pair<int, int> size, const py::object& ids,
           const py::kwargs& kwargs) {
          const auto p = Rows<3>(points, "points_in_world");
          const auto q = Rows<2>(pixels, "pixels");
          return Fit(p, q, IdsOf(ids, q.size()), SizeOf(size), ArgumentsOf(kwargs));
        },
        "fit(points_in_world, pixels, image_size, *, ids=None, **options) -> Camera\n\n`camproj fit` on arrays: points_in_world (N, 3) in world units seen at pixels (N, 2) in px (OpenCV origin unless pixel_origin=\"corner\"); image_size (width, height) px. Options are the command line's with '-' as '_' (model, criterion, free, fix, focal [px], fovy_deg, aspect, principal_point, skew, k1, k2, intrinsics, pixel_origin, loss, keep_all, ransac_px, sigma [px], max_uncertainty [px], object_points_in_world, near, far, bounds (6 numbers), bounds_mesh (an OBJ / PLY path or (M, 3) vertices: near and far cover them and the camera is judged at them), origin, max_iterations). Raises a SceneError subclass with the command line's message when the points cannot determine the camera, ValueError for a bad argument. Conventions: docs/conventions.md.",
        py::arg("points_in_world"), py::arg("pixels"), py::arg("image_size"), py::kw_only(),
        py::arg("ids") = py::none());
  m.def("fit_file",
        [](const std::string& path, std::pair<int, int> size, const py::kwargs& kwargs) {
          const FitArguments arguments = ArgumentsOf(kwargs);
          const Correspondences data = ReadCorrespondencesFile(path);
          return Fit(data.points_in_world, data.pixels, data.ids, SizeOf(size), arguments);
        },
        "fit_file(path, image_size, **options) -> Camera: fit() on a points CSV (ids from its id column).",
        py::arg("path"), py::arg("image_size"));

  m.def("read_camera", [](const std::string& path) {
    PyCamera c;
    c.camera = ReadCameraFile(path);
    return c;
  }, py::arg("path"));
  m.def("camera_from_json", [](const std::string& text, const std::string& source) {
    PyCamera c;
    c.camera = CameraFromJsonText(text, source);
    return c;
  }, py::arg("text"), py::arg("source") = "<string>");

  m.def("read_points", [](const std::string& path) {
    const Correspondences d = ReadCorrespondencesFile(path);
    return py::make_tuple(ToArray<3>(d.points_in_world), ToArray<2>(d.pixels), d.ids);
  }, py::arg("path"));
  m.def("points_from_csv", [](const std::string& text, const std::string& source) {
    const Correspondences d = CorrespondencesFromCsvText(text, source);
    return py::make_tuple(ToArray<3>(d.points_in_world), ToArray<2>(d.pixels), d.ids);
  }, py::arg("text"), py::arg("source") = "<string>");
  m.def("points_to_csv", [](const Array& points, const Array& pixels, const py::object& ids) {
    Correspondences d;
    d.points_in_world = Rows<3>(points, "points_in_world");
    d.pixels = Rows<2>(pixels, "pixels");
    d.ids = IdsOf(ids, d.pixels.size());
    return CorrespondencesToCsvText(d);
  }, py::arg("points_in_world"), py::arg("pixels"), py::arg("ids") = py::none());
  m.def("write_points", [](const std::string& path, const Array& points, const Array& pixels,
                           const py::object& ids) {
    Correspondences d;
    d.points_in_world = Rows<3>(points, "points_in_world");
    d.pixels = Rows<2>(pixels, "pixels");
    d.ids = IdsOf(ids, d.pixels.size());
    WriteFileAtomically(path, CorrespondencesToCsvText(d));
  }, py::arg("path"), py::arg("points_in_world"), py::arg("pixels"), py::arg("ids") = py::none());

  // Conversions (gl.h, frustum.h, look_at.h).
  m.def("gl_projection_from_K",
        [](const Eigen::Matrix3d& K, std::pair<int, int> size, double n, double f,
           const std::string& depth, bool reversed_z, const std::string& origin) {
          return ClipFromGlEye(IntrinsicsFromK(K), SizeOf(size), n, f, DepthOf(depth, reversed_z),
                               PixelOriginFromString(origin));
        },
        "clip_from_gl_eye (4x4) of pinhole K (px, skew included) for image_size; depth \"no\"|\"zo\", reversed_z, far=math.inf for an infinite far plane; pixel_origin of cx, cy.",
        py::arg("K"), py::arg("image_size"), py::arg("near"), py::arg("far"),
        py::arg("depth") = "no", py::arg("reversed_z") = false, py::arg("pixel_origin") = "center");
  m.def("K_from_gl_projection",
        [](const Eigen::Matrix4d& P, std::pair<int, int> size, const std::string& origin) {
          return IntrinsicsFromClipFromGlEye(P, SizeOf(size), PixelOriginFromString(origin)).K();
        },
        "K (3x3, px) of a perspective clip_from_gl_eye for image_size (cx, cy in pixel_origin).",
        py::arg("clip_from_gl_eye"), py::arg("image_size"), py::arg("pixel_origin") = "center");
  m.def("depth_range_from_gl_projection",
        [](const Eigen::Matrix4d& P, const std::string& depth, bool reversed_z) {
          const DepthRange r = DepthRangeFromClipFromGlEye(P, DepthOf(depth, reversed_z));
          return py::make_tuple(r.z_near, r.z_far);
        },
        py::arg("clip_from_gl_eye"), py::arg("depth") = "no", py::arg("reversed_z") = false);
  m.def("gl_projection_from_frustum",
        [](const Frustum& f, const std::string& depth, bool reversed_z) {
          return ClipFromGlEye(f, DepthOf(depth, reversed_z));
        },
        py::arg("frustum"), py::arg("depth") = "no", py::arg("reversed_z") = false);
  m.def("gl_projection_from_perspective",
        [](const Perspective& p, const std::string& depth, bool reversed_z) {
          return ClipFromGlEye(p, DepthOf(depth, reversed_z));
        },
        py::arg("perspective"), py::arg("depth") = "no", py::arg("reversed_z") = false);
  m.def("frustum_from_gl_projection",
        [](const Eigen::Matrix4d& P, const std::string& depth, bool reversed_z) {
          return FrustumFromClipFromGlEye(P, DepthOf(depth, reversed_z));
        },
        py::arg("clip_from_gl_eye"), py::arg("depth") = "no", py::arg("reversed_z") = false);
  m.def("frustum_from_perspective", &FrustumFromPerspective, py::arg("perspective"));
  m.def("perspective_from_frustum", &PerspectiveFromFrustum, py::arg("frustum"));
  m.def("frustum_from_K",
        [](const Eigen::Matrix3d& K, std::pair<int, int> size, double n, double f, const std::string& origin) {
          return FrustumFromIntrinsics(IntrinsicsFromK(K), SizeOf(size), n, f, PixelOriginFromString(origin));
        },
        py::arg("K"), py::arg("image_size"), py::arg("near"), py::arg("far"),
        py::arg("pixel_origin") = "center");
  m.def("K_from_frustum",
        [](const Frustum& f, std::pair<int, int> size, const std::string& origin) {
          return IntrinsicsFromFrustum(f, SizeOf(size), PixelOriginFromString(origin)).K();
        },
        py::arg("frustum"), py::arg("image_size"), py::arg("pixel_origin") = "center");
  m.def("cam_from_world_from_look_at",
        [](const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
          const Rigid3 pose = CamFromWorldFromLookAt(LookAt{eye, target, up});
          return py::make_tuple(pose.rotation, pose.translation);
        },
        "(R, t) of gluLookAt(eye, target, up), world units.",
        py::arg("eye"), py::arg("target"), py::arg("up"));
  m.def("look_at_from_cam_from_world",
        [](const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double target_distance) {
          const LookAt l = LookAtFromCamFromWorld(PoseOf(R, t), target_distance);
          return py::make_tuple(l.eye, l.target, l.up);
        },
        "(eye, target, up): target at target_distance along the gaze.",
        py::arg("R"), py::arg("t"), py::arg("target_distance") = 1.0);
  m.def("gl_view_from_cam_from_world",
        [](const Eigen::Matrix3d& R, const Eigen::Vector3d& t) { return GlEyeFromWorld(PoseOf(R, t)); },
        py::arg("R"), py::arg("t"));
  m.def("cam_from_world_from_gl_view",
        [](const Eigen::Matrix4d& V) {
          const Rigid3 pose = CamFromWorldFromGlEyeFromWorld(V);
          return py::make_tuple(pose.rotation, pose.translation);
        },
        py::arg("gl_eye_from_world"));
  m.def("pixel_origin_shift",
        [](const std::string& from, const std::string& to) {
          return PixelOriginShift(PixelOriginFromString(from), PixelOriginFromString(to));
        },
        py::arg("from_origin"), py::arg("to_origin"));
  m.def("write_file_atomically", &WriteFileAtomically, py::arg("path"), py::arg("contents"),
        "Writes text as camproj fit -o does (file_io.h): readers see the old file or the new one, "
        "never a partial one; flushed to disk before the rename.");
  m.attr("EXPORT_FORMATS") = py::make_tuple("gl", "glm", "opencv-yaml", "colmap", "three", "json",
                                            "glsl", "distortion-mesh");
}
