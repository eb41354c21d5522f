// The `camproj` Python module: a thin pybind11 layer over the library's public API
// (lib/include/camproj/). No geometry here: every number comes from a library call; this file
// converts numpy arrays, strings and exceptions. Conventions: docs/conventions.md; the Python
// API, with units, is in camproj.pyi.
#include <array>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

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
#include "camproj/number_text.h"
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

// `value`'s Python type, for messages: "str", "numpy.ndarray".
std::string TypeName(const py::handle& value) {
  const py::handle type = py::type::handle_of(value);
  const std::string module = py::str(type.attr("__module__"));
  const std::string name = py::str(type.attr("__qualname__"));
  return module == "builtins" ? name : module + "." + name;
}

// "'1500' (str)": a value as a message shows it.
std::string Shown(const py::handle& value) {
  std::string text = py::repr(value);
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text + " (" + TypeName(value) + ")";
}

// An (N, columns) array of real numbers (numpy array or nested sequences, any real dtype) -> N
// vectors. ValueError naming `name` and the shape; TypeError for None, booleans, complex numbers
// or text, which a cast to float64 would take silently or with only a warning.
template <int kColumns>
std::vector<Eigen::Matrix<double, kColumns, 1>> Rows(const py::handle& value, const char* name) {
  if (value.is_none()) {
    throw py::type_error(std::string(name) + ": expected an (N, " + std::to_string(kColumns) +
                         ") array, got None");
  }
  const py::array any = py::module_::import("numpy").attr("asarray")(value);
  const char kind = any.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::type_error(std::string(name) + ": expected real numbers, got an array of " +
                         std::string(py::str(any.dtype())));
  }
  const Array array = Array::ensure(any);
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

// A path given as str, bytes or os.PathLike, or nullopt for anything else.
std::optional<std::string> PathOf(const py::handle& value) {
  if (!py::isinstance<py::str>(value) && !py::isinstance<py::bytes>(value) &&
      !py::hasattr(value, "__fspath__")) {
    return std::nullopt;
  }
  return py::module_::import("os").attr("fsdecode")(value).cast<std::string>();
}

// Runs `work` with the GIL released, so fits in threads of one process run in parallel.
// Not py::gil_scoped_release: its destructor takes the GIL back, and a daemon thread that does
// so while the interpreter exits is ended by pthread_exit, whose forced unwind through a noexcept
// destructor aborts the process. Here the GIL is taken back in plain code, outside the try.
template <class Work>
auto WithoutGil(Work&& work) -> decltype(work()) {
  std::optional<decltype(work())> result;
  std::exception_ptr error;
  PyThreadState* const state = PyEval_SaveThread();
  try {
    result.emplace(work());
  } catch (...) {
    error = std::current_exception();
  }
  PyEval_RestoreThread(state);
  if (error) std::rethrow_exception(error);
  return std::move(*result);
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

// The value types' fields in constructor order: what __eq__ compares and pickle stores.
std::array<double, 10> FieldsOf(const Intrinsics& k) {
  return {k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2, k.p1, k.p2, k.k3};
}
std::array<double, 6> FieldsOf(const Frustum& f) {
  return {f.left, f.right, f.bottom, f.top, f.z_near, f.z_far};
}
std::array<double, 4> FieldsOf(const Perspective& p) {
  return {p.fovy_deg, p.aspect, p.z_near, p.z_far};
}

// fit()'s option values, each checked as the command line checks its option: TypeError naming
// the option for a value of the wrong type, ValueError for a wrong value.
class OptionValue {
 public:
  OptionValue(const std::string& name, const py::handle& value) : name_(name), value_(value) {}

  const py::handle& value() const { return value_; }
  // Throws Error("NAME: expected EXPECTED, got GOT").
  template <class Error>
  [[noreturn]] void Fail(const std::string& expected, const std::string& got) const {
    throw Error(name_ + ": expected " + expected + ", got " + got);
  }

  // A finite real number (int, float, numpy scalar; not bool).
  double Number() const { return NumberAt(value_, name_); }
  double Positive() const {
    const double v = Number();
    if (!(v > 0.0)) Fail<std::invalid_argument>("a positive number", ShortestDouble(v));
    return v;
  }
  // Exactly `count` numbers, as a sequence (list, tuple, array).
  std::vector<double> Numbers(size_t count) const {
    if (py::isinstance<py::str>(value_) || !py::isinstance<py::sequence>(value_)) {
      Fail<py::type_error>(std::to_string(count) + " numbers", Shown(value_));
    }
    const py::sequence sequence = py::reinterpret_borrow<py::sequence>(value_);
    if (sequence.size() != count) {
      Fail<std::invalid_argument>(std::to_string(count) + " numbers",
                                  std::to_string(sequence.size()));
    }
    std::vector<double> numbers;
    for (size_t i = 0; i < count; ++i) {
      numbers.push_back(NumberAt(sequence[i], name_ + "[" + std::to_string(i) + "]"));
    }
    return numbers;
  }
  int NonNegativeInteger() const {
    long long v = 0;
    try {
      if (py::isinstance<py::bool_>(value_)) throw py::cast_error();
      v = value_.cast<long long>();  // refuses floats; numpy integers convert
    } catch (const py::cast_error&) {
      if (!py::isinstance<py::int_>(value_)) Fail<py::type_error>("an integer", Shown(value_));
      v = -1;  // an int beyond 64 bits
    }
    if (v < 0 || v > std::numeric_limits<int>::max()) {
      Fail<std::invalid_argument>("an integer from 0 to 2147483647",
                                  std::string(py::repr(value_)));
    }
    return static_cast<int>(v);
  }
  bool Bool() const {
    if (!py::isinstance<py::bool_>(value_) && TypeName(value_) != "numpy.bool_") {
      Fail<py::type_error>("True or False", Shown(value_));
    }
    return value_.cast<bool>();
  }
  std::string String() const {
    if (!py::isinstance<py::str>(value_)) Fail<py::type_error>("a string", Shown(value_));
    return value_.cast<std::string>();
  }
  // Names, as a sequence of strings or one string split at commas (as the command line's
  // --free focal,aspect).
  std::vector<std::string> Names() const {
    std::vector<std::string> names;
    if (py::isinstance<py::str>(value_)) {
      std::string text = value_.cast<std::string>();
      for (size_t begin = 0;;) {
        const size_t comma = text.find(',', begin);
        names.push_back(text.substr(begin, comma - begin));
        if (comma == std::string::npos) return names;
        begin = comma + 1;
      }
    }
    if (!py::isinstance<py::sequence>(value_)) {
      Fail<py::type_error>("a sequence of names", Shown(value_));
    }
    for (const py::handle item : py::reinterpret_borrow<py::sequence>(value_)) {
      if (!py::isinstance<py::str>(item)) {
        Fail<py::type_error>("a sequence of names", "an item " + Shown(item));
      }
      names.push_back(item.cast<std::string>());
    }
    return names;
  }

 private:
  double NumberAt(const py::handle& value, const std::string& name) const {
    double v = 0.0;
    try {
      if (py::isinstance<py::bool_>(value) || py::isinstance<py::str>(value)) throw py::cast_error();
      v = value.cast<double>();
    } catch (const py::cast_error&) {
      throw py::type_error(name + ": expected a number, got " + Shown(value));
    }
    if (!std::isfinite(v)) {
      throw std::invalid_argument(name + ": expected a finite number, got " + ShortestDouble(v));
    }
    return v;
  }

  std::string name_;
  py::handle value_;
};

// Reads one fit() option into the command line's arguments.
using OptionReader = void (*)(const OptionValue& v, FitArguments& a);

// fit()'s options, by name (the command line's with '-' as '_'; camproj.pyi lists them).
const std::map<std::string, OptionReader>& OptionReaders() {
  static const auto& readers = *new std::map<std::string, OptionReader>{
      {"model", [](const OptionValue& v, FitArguments& a) { a.model = v.String(); }},
      {"criterion", [](const OptionValue& v, FitArguments& a) { a.criterion = v.String(); }},
      {"free", [](const OptionValue& v, FitArguments& a) { a.free = v.Names(); }},
      {"fix", [](const OptionValue& v, FitArguments& a) { a.fix = v.Names(); }},
      {"focal", [](const OptionValue& v, FitArguments& a) { a.focal = v.Positive(); }},
      {"fovy_deg", [](const OptionValue& v, FitArguments& a) { a.fovy_deg = v.Positive(); }},
      {"aspect", [](const OptionValue& v, FitArguments& a) { a.aspect = v.Positive(); }},
      {"principal_point",
       [](const OptionValue& v, FitArguments& a) {
         const std::vector<double> c = v.Numbers(2);
         a.principal_point = Eigen::Vector2d(c[0], c[1]);
       }},
      {"skew", [](const OptionValue& v, FitArguments& a) { a.skew = v.Number(); }},
      {"k1", [](const OptionValue& v, FitArguments& a) { a.k1 = v.Number(); }},
      {"k2", [](const OptionValue& v, FitArguments& a) { a.k2 = v.Number(); }},
      {"intrinsics",
       [](const OptionValue& v, FitArguments& a) {
         if (const auto path = PathOf(v.value())) {
           a.known_intrinsics = ReadIntrinsicsFile(*path, &a.known_intrinsics_image_size);
           a.known_intrinsics_path = *path;
         } else if (py::isinstance<Intrinsics>(v.value())) {
           a.known_intrinsics = v.value().cast<Intrinsics>();
         } else {
           v.Fail<py::type_error>("a camproj.Intrinsics or the path of a camera file",
                                  Shown(v.value()));
         }
       }},
      {"pixel_origin", [](const OptionValue& v, FitArguments& a) { a.pixel_origin = v.String(); }},
      {"loss", [](const OptionValue& v, FitArguments& a) { a.loss = v.String(); }},
      {"refiner", [](const OptionValue& v, FitArguments& a) { a.refiner = v.String(); }},
      {"keep_all", [](const OptionValue& v, FitArguments& a) { a.keep_all = v.Bool(); }},
      {"ransac_px", [](const OptionValue& v, FitArguments& a) { a.ransac_px = v.Positive(); }},
      {"sigma", [](const OptionValue& v, FitArguments& a) { a.sigma = v.Positive(); }},
      {"max_uncertainty",
       [](const OptionValue& v, FitArguments& a) { a.max_uncertainty = v.Positive(); }},
      {"object_points_in_world",
       [](const OptionValue& v, FitArguments& a) {
         if (const auto path = PathOf(v.value())) {
           CorrespondencesLimits limits;  // as --object-points reads its file: pixels optional
           limits.read_pixels = false;
           a.object_points_in_world = ReadCorrespondencesFile(*path, limits).points_in_world;
         } else {
           a.object_points_in_world = Rows<3>(v.value(), "object_points_in_world");
         }
       }},
      {"near", [](const OptionValue& v, FitArguments& a) { a.z_near = v.Positive(); }},
      {"far", [](const OptionValue& v, FitArguments& a) { a.z_far = v.Positive(); }},
      {"bounds",
       [](const OptionValue& v, FitArguments& a) {
         const std::vector<double> b = v.Numbers(6);
         a.bounds_in_world = BoxInWorld{{b[0], b[1], b[2]}, {b[3], b[4], b[5]}};
       }},
      {"bounds_mesh",
       [](const OptionValue& v, FitArguments& a) {
         const auto path = PathOf(v.value());
         a.mesh_vertices_in_world =
             path ? ReadMeshVertices(*path) : Rows<3>(v.value(), "bounds_mesh");
         // An empty mesh file is refused by its reader; so is an empty array (not "no mesh").
         if (a.mesh_vertices_in_world.empty()) {
           throw std::invalid_argument("bounds_mesh: no vertices");
         }
       }},
      {"origin",
       [](const OptionValue& v, FitArguments& a) {
         if (!py::isinstance<py::str>(v.value())) {
           const std::vector<double> o = v.Numbers(3);
           a.world_origin = Eigen::Vector3d(o[0], o[1], o[2]);
         } else if (v.String() == "auto") {
           a.auto_world_origin = true;
         } else {
           v.Fail<std::invalid_argument>("\"auto\" or 3 numbers X, Y, Z", Shown(v.value()));
         }
       }},
      {"max_iterations",
       [](const OptionValue& v, FitArguments& a) { a.max_iterations = v.NonNegativeInteger(); }},
  };
  return readers;
}

// fit()'s keyword arguments -> the command line's FitArguments (fit_request.h); None is "not
// given". The name is checked first, so that a misspelled option is never ignored.
FitArguments ArgumentsOf(const py::kwargs& kwargs) {
  FitArguments a;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    const auto reader = OptionReaders().find(name);
    if (reader == OptionReaders().end()) {
      throw std::invalid_argument("fit: unknown option \"" + name + "\" (see help(camproj.fit))");
    }
    if (!value.is_none()) reader->second(OptionValue(name, value), a);
  }
  return a;
}

PyCamera Fit(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector2d>& pixels,
             const std::vector<std::string>& ids, const ImageSize& size, const FitArguments& arguments) {
  const FitRequest request = FitRequestFrom(arguments, size);
  PyCamera result;
  result.fit = WithoutGil([&] {
    return std::make_shared<const FitResult>(RunFitRequest(points, pixels, ids, size, request));
  });
  result.camera = result.fit->camera;
  result.target_distance =
      (result.fit->views.look_at.target - result.fit->views.look_at.eye).stableNorm();
  result.ids = ids;
  result.input_origin = request.options().pixel_origin;
  return result;
}

// Point ids: strings (or integers, written as text), one per point, that a points file could
// hold (CheckPointIds); none: the points are numbered from 1.
std::vector<std::string> IdsOf(const py::object& ids, size_t count) {
  if (ids.is_none()) return {};
  if (py::isinstance<py::str>(ids) || !py::isinstance<py::sequence>(ids)) {
    throw py::type_error("ids: expected a sequence of strings, got " + Shown(ids));
  }
  std::vector<std::string> list;
  for (const py::handle id : py::reinterpret_borrow<py::sequence>(ids)) {
    if (py::isinstance<py::str>(id)) {
      list.push_back(id.cast<std::string>());
    } else if (!py::isinstance<py::bool_>(id) && py::hasattr(id, "__index__")) {
      list.push_back(py::str(py::int_(py::reinterpret_borrow<py::object>(id))));
    } else {
      throw py::type_error("ids: expected strings or integers, got " + Shown(id));
    }
  }
  if (list.size() != count) {
    throw std::invalid_argument("ids: expected one per point (" + std::to_string(count) + "), got " +
                                std::to_string(list.size()));
  }
  try {
    CheckPointIds(list);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("ids: ") + e.what());
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
      // Values compare equal field by field (bit for bit but -0 == 0); pickled as those fields.
      .def("__eq__", [](const Intrinsics& a, const Intrinsics& b) { return FieldsOf(a) == FieldsOf(b); },
           py::is_operator())
      .def(py::pickle([](const Intrinsics& k) { return FieldsOf(k); },
                      [](const std::array<double, 10>& f) {
                        Intrinsics k{f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8], f[9]};
                        k.Check();
                        return k;
                      }))
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
      .def("__eq__", [](const Frustum& a, const Frustum& b) { return FieldsOf(a) == FieldsOf(b); },
           py::is_operator())
      .def(py::pickle([](const Frustum& f) { return FieldsOf(f); },
                      [](const std::array<double, 6>& t) {
                        Frustum f{t[0], t[1], t[2], t[3], t[4], t[5]};
                        f.Check();
                        return f;
                      }))
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
      .def("__eq__",
           [](const Perspective& a, const Perspective& b) { return FieldsOf(a) == FieldsOf(b); },
           py::is_operator())
      .def(py::pickle([](const Perspective& p) { return FieldsOf(p); },
                      [](const std::array<double, 4>& t) {
                        Perspective p{t[0], t[1], t[2], t[3]};
                        p.Check();
                        return p;
                      }))
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
             if (!(std::isfinite(target_distance) && target_distance > 0.0)) {
               throw std::invalid_argument("target_distance: expected a positive finite number, got " +
                                           ShortestDouble(target_distance));
             }
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
                             "(docs/conventions.md, section 12).")
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
           [](const PyCamera& c, const py::object& points) {
             const auto rows = Rows<3>(points, "points_in_world");
             std::vector<Eigen::Vector2d> pixels(rows.size());
             for (size_t i = 0; i < rows.size(); ++i) {
               // A NaN row out means "not in front of the camera"; a NaN row in is a mistake.
               if (!rows[i].allFinite()) {
                 throw std::invalid_argument("points_in_world[" + std::to_string(i) +
                                             "] is not finite: " + ShortestDouble(rows[i].x()) +
                                             ", " + ShortestDouble(rows[i].y()) + ", " +
                                             ShortestDouble(rows[i].z()));
               }
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
           [](const PyCamera& c, const std::filesystem::path& path, std::optional<std::string> origin) {
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
        [](const py::object& points, const py::object& pixels, std::pair<int, int> size, const py::object& ids,
           const py::kwargs& kwargs) {
          const auto p = Rows<3>(points, "points_in_world");
          const auto q = Rows<2>(pixels, "pixels");
          return Fit(p, q, IdsOf(ids, q.size()), SizeOf(size), ArgumentsOf(kwargs));
        },
        "fit(points_in_world, pixels, image_size, *, ids=None, **options) -> Camera\n\n`camproj fit` on arrays: points_in_world (N, 3) in world units seen at pixels (N, 2) in px (OpenCV origin unless pixel_origin=\"corner\"); image_size (width, height) px. Options are the command line's with '-' as '_' (model, criterion, free, fix, focal [px], fovy_deg, aspect, principal_point, skew, k1, k2, intrinsics, pixel_origin, loss, refiner, keep_all, ransac_px, sigma [px], max_uncertainty [px], object_points_in_world, near, far, bounds (6 numbers), bounds_mesh (an OBJ / PLY path or (M, 3) vertices: near and far cover them and the camera is judged at them), origin, max_iterations). Raises a SceneError subclass with the command line's message when the points cannot determine the camera, ValueError for a bad argument. Conventions: docs/conventions.md.",
        py::arg("points_in_world"), py::arg("pixels"), py::arg("image_size"), py::kw_only(),
        py::arg("ids") = py::none());
  m.def("fit_file",
        [](const std::filesystem::path& path, std::pair<int, int> size, const py::kwargs& kwargs) {
          const FitArguments arguments = ArgumentsOf(kwargs);
          const Correspondences data = ReadCorrespondencesFile(path);
          return Fit(data.points_in_world, data.pixels, data.ids, SizeOf(size), arguments);
        },
        "fit_file(path, image_size, **options) -> Camera: fit() on a points CSV (ids from its id column).",
        py::arg("path"), py::arg("image_size"));

  m.def("read_camera", [](const std::filesystem::path& path) {
    PyCamera c;
    c.camera = ReadCameraFile(path);
    return c;
  }, py::arg("path"));
  m.def("camera_from_json", [](const std::string& text, const std::string& source) {
    PyCamera c;
    c.camera = CameraFromJsonText(text, source);
    return c;
  }, py::arg("text"), py::arg("source") = "<string>");

  m.def("read_points", [](const std::filesystem::path& path) {
    const Correspondences d = ReadCorrespondencesFile(path);
    return py::make_tuple(ToArray<3>(d.points_in_world), ToArray<2>(d.pixels), d.ids);
  }, py::arg("path"));
  m.def("points_from_csv", [](const std::string& text, const std::string& source) {
    const Correspondences d = CorrespondencesFromCsvText(text, source);
    return py::make_tuple(ToArray<3>(d.points_in_world), ToArray<2>(d.pixels), d.ids);
  }, py::arg("text"), py::arg("source") = "<string>");
  m.def("points_to_csv", [](const py::object& points, const py::object& pixels, const py::object& ids) {
    Correspondences d;
    d.points_in_world = Rows<3>(points, "points_in_world");
    d.pixels = Rows<2>(pixels, "pixels");
    d.ids = IdsOf(ids, d.pixels.size());
    return CorrespondencesToCsvText(d);
  }, py::arg("points_in_world"), py::arg("pixels"), py::arg("ids") = py::none());
  m.def("write_points", [](const std::filesystem::path& path, const py::object& points, const py::object& pixels,
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
  m.def("write_file_atomically",
        [](const std::filesystem::path& path, const std::string& contents) {
          WriteFileAtomically(path, contents);
        },
        py::arg("path"), py::arg("contents"),
        "Writes text as camproj fit -o does (file_io.h): readers see the old file or the new one, "
        "never a partial one; flushed to disk before the rename.");
  m.attr("EXPORT_FORMATS") = py::make_tuple("gl", "glm", "opencv-yaml", "colmap", "three", "json",
                                            "glsl", "distortion-mesh");
}
