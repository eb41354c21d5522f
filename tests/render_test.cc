// End-to-end check of the GL matrices with a real OpenGL renderer (Mesa, headless EGL): a scene is
// drawn through ClipFromGlEye and GlEyeFromWorld into a float framebuffer whose fragment shader
// writes the (perspective-correctly interpolated) world position it sees. For every covered pixel
// the test projects that world point with K [R|t] in double (PixelFromCam) and requires it to land
// on the pixel's centre, and compares the depth buffer with the window depth the pinhole depth
// predicts for the requested depth convention.
//
// Pixel correspondence, derived here independently of the library: the GL samples fragment
// (i, j) at window (i + 0.5, j + 0.5), with glReadPixels row j = 0 at the bottom; camproj's
// kCenter convention has x_win = u + 0.5, y_win = H - (v + 0.5). So GL pixel (i, j) is image
// pixel (u, v) = (i, H - 1 - j).
//
// Without an EGL display or a suitable context (e.g. no Mesa surfaceless platform) every test is
// reported as skipped, with the reason; anything that goes wrong once the context exists fails.

#define GL_GLEXT_PROTOTYPES 1

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <ostream>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camproj/conventions.h"
#include "camproj/gl.h"
#include "camproj/camera.h"
#include "camproj/intrinsics.h"
#include "camproj/look_at.h"
#include "camproj/pose.h"
#include "camproj/world_origin.h"

namespace camproj {
namespace {

// Largest distance between the GL pixel centre and K [R|t] of the world point read back there.
// Error budget, with focal lengths ~150 px, scene points |X| <= ~17 world units and depths Z of
// ~2.5 to ~20: float32 rounding of the uploaded matrices and vertices (relative 6e-8) moves a
// projected point by ~6e-8 * f * (|X| + |t|) / Z ~ 1e-5 px; the rasterizer's float plane
// equations and the perspective divide of the varying cost a few ulps of |X| (~1e-6 world
// units), i.e. ~f * 1e-6 / Z ~ 1e-4 px at most. Measured: <= 4e-5 px (llvmpipe and softpipe).
// 1e-3 px leaves room for other drivers yet is 500x below the half-pixel offset it catches.
constexpr double kMaxPixelError = 1e-3;

// Largest difference between the depth buffer (GL_DEPTH_COMPONENT32F) and the window depth
// predicted in double from the read-back point. Window depths lie in [0, 1], where float32 has an
// ulp of at most 6e-8; the divide, the depth-range scale and the interpolation of the depth plane
// cost a few ulps each. (The point's own float error, ~1e-6 in Z, moves the predicted depth by
// only ~n / Z^2 * 1e-6 ~ 1e-7.) Measured: <= 1.6e-7 (llvmpipe and softpipe); 1e-6 is ~16 ulps
// near 1.
constexpr double kMaxDepthError = 1e-6;

// Fraction of the image the scene must cover: the background is built to fill the view of every
// camera, so anything less means the geometry or the matrices are off.
constexpr double kMinCoveredFraction = 0.99;

// Distance (world units) within which a read-back point counts as lying on a scene plane: float32
// interpolation leaves ~1e-6; the box is 1 unit wide, so 1e-4 cannot confuse its faces.
constexpr double kOnPlaneTolerance = 1e-4;

// Each camera-facing box face and the background must show at least this many pixels, so that
// the depth test and several non-coplanar surfaces are really exercised.
constexpr int kMinPixelsPerSurface = 200;

constexpr ImageSize kImageSize = {160, 120};
constexpr double kZNear = 0.5;
constexpr double kZFar = 40.0;
constexpr double kBoxHalfSize = 0.5;  // the box is [-0.5, 0.5]^3 in world
// The background is the plane n . X = kBackgroundOffset with n = (1, 1, 1)/sqrt(3): behind the
// box for cameras in the (+, +, +) octant, and tilted with respect to all of their gazes.
constexpr double kBackgroundOffset = -2.0;
constexpr double kBackgroundHalfSize = 12.0;
constexpr int kBackgroundGrid = 32;  // quads per side; see SceneTriangles()

// ---------------------------------------------------------------------------------------------
// Headless GL context.

bool HasExtension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const size_t length = std::strlen(name);
  for (const char* p = extensions; (p = std::strstr(p, name)) != nullptr; p += length) {
    const bool starts = p == extensions || p[-1] == ' ';
    const bool ends = p[length] == '\0' || p[length] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

std::string EglErrorText() {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "EGL error 0x%04X", static_cast<unsigned>(eglGetError()));
  return buffer;
}

// An OpenGL >= 4.5 core (or 3.3 core with ARB_clip_control) context made current without a
// surface on Mesa's surfaceless EGL platform. Rendering goes to framebuffer objects only.
class HeadlessGlContext {
 public:
  // The current context, or nullptr with *why_not saying what is missing.
  static std::unique_ptr<HeadlessGlContext> Create(std::string* why_not) {
    std::unique_ptr<HeadlessGlContext> context(new HeadlessGlContext());
    *why_not = context->Initialize();
    if (!why_not->empty()) return nullptr;
    return context;
  }

  // The display is deliberately not eglTerminate()d: Mesa would dlclose() its driver, orphaning
  // the driver's global caches, which LeakSanitizer then reports as leaks (112 bytes after a
  // draw; none when the driver is kept loaded). EGL displays are per-process and exit frees them.
  ~HeadlessGlContext() {
    if (display_ == EGL_NO_DISPLAY) return;
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
    eglReleaseThread();
  }

  HeadlessGlContext(const HeadlessGlContext&) = delete;
  HeadlessGlContext& operator=(const HeadlessGlContext&) = delete;

  const std::string& description() const { return description_; }

 private:
  HeadlessGlContext() = default;

  // Returns "" on success, else why no context could be made.
  std::string Initialize() {
    const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!HasExtension(client_extensions, "EGL_MESA_platform_surfaceless")) {
      return "EGL client extension EGL_MESA_platform_surfaceless is not available";
    }
    const auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) return "eglGetPlatformDisplayEXT is not available";
    display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display_ == EGL_NO_DISPLAY) return "no surfaceless EGL display: " + EglErrorText();
    EGLint major = 0;
    EGLint minor = 0;
    if (!eglInitialize(display_, &major, &minor)) {
      const std::string error = "eglInitialize failed: " + EglErrorText();
      display_ = EGL_NO_DISPLAY;
      return error;
    }
    const char* display_extensions = eglQueryString(display_, EGL_EXTENSIONS);
    if (!HasExtension(display_extensions, "EGL_KHR_surfaceless_context")) {
      return "EGL_KHR_surfaceless_context is not available";
    }
    if (!eglBindAPI(EGL_OPENGL_API)) return "eglBindAPI(EGL_OPENGL_API) failed: " + EglErrorText();

    EGLConfig config = nullptr;  // EGL_NO_CONFIG_KHR
    EGLint config_count = 0;
    for (const EGLint surface_type : {EGL_PBUFFER_BIT, 0}) {
      const EGLint attributes[] = {EGL_SURFACE_TYPE, surface_type, EGL_RENDERABLE_TYPE,
                                   EGL_OPENGL_BIT, EGL_NONE};
      if (eglChooseConfig(display_, attributes, &config, 1, &config_count) && config_count > 0) {
        break;
      }
    }
    if (config_count == 0) {
      if (!HasExtension(display_extensions, "EGL_KHR_no_config_context")) {
        return "no EGL config renders with OpenGL";
      }
      config = nullptr;
    }

    // 4.5 has glClipControl in core; 3.3 will do with ARB_clip_control.
    constexpr EGLint kVersions[][2] = {{4, 5}, {3, 3}};
    for (const auto& version : kVersions) {
      const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                   version[0],
                                   EGL_CONTEXT_MINOR_VERSION,
                                   version[1],
                                   EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                   EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                   EGL_NONE};
      context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, attributes);
      if (context_ != EGL_NO_CONTEXT) break;
    }
    if (context_ == EGL_NO_CONTEXT) {
      return "no OpenGL 4.5 or 3.3 core context: " + EglErrorText();
    }
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      return "eglMakeCurrent without a surface failed: " + EglErrorText();
    }

    GLint gl_major = 0;
    GLint gl_minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &gl_major);
    glGetIntegerv(GL_MINOR_VERSION, &gl_minor);
    bool has_clip_control = gl_major > 4 || (gl_major == 4 && gl_minor >= 5);
    GLint extension_count = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &extension_count);
    for (GLint i = 0; i < extension_count && !has_clip_control; ++i) {
      const auto* name = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, i));
      has_clip_control = name != nullptr && std::strcmp(name, "GL_ARB_clip_control") == 0;
    }
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    description_ = std::string(renderer ? renderer : "?") + ", OpenGL " + (version ? version : "?");
    if (!has_clip_control) return "no glClipControl (GL 4.5 or ARB_clip_control): " + description_;
    return "";
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string description_;
};

// ---------------------------------------------------------------------------------------------
// GL helpers. Each returns "" on success or a message for the test to fail with.

std::string GlErrorText(const char* where) {
  const GLenum error = glGetError();
  if (error == GL_NO_ERROR) return "";
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "GL error 0x%04X after %s", error, where);
  return buffer;
}

std::string CompileShader(GLenum type, const char* source, GLuint* shader) {
  *shader = glCreateShader(type);
  glShaderSource(*shader, 1, &source, nullptr);
  glCompileShader(*shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(*shader, GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return "";
  char log[2048] = "";
  glGetShaderInfoLog(*shader, sizeof(log), nullptr, log);
  return std::string("shader compilation failed: ") + log;
}

// `world_position` is what the GL draws; `reported_position` is what the fragment writes back:
// the same numbers, except in the survey-scale test, where the GL draws float32 survey
// coordinates and the read-back is the exact point relative to the scene (see SurveyScaleTest).
constexpr char kVertexShader[] = R"(#version 330 core
uniform mat4 u_projection;
uniform mat4 u_view;
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 reported_position;
out vec3 v_world_position;  // smooth: perspective-correct
void main() {
  v_world_position = reported_position;
  gl_Position = u_projection * u_view * vec4(world_position, 1.0);
}
)";

constexpr char kFragmentShader[] = R"(#version 330 core
in vec3 v_world_position;
layout(location = 0) out vec4 color;
void main() { color = vec4(v_world_position, 1.0); }
)";

// The program, vertex buffer and framebuffer of one rendering; deleted with the object.
struct GlObjects {
  GLuint vertex_shader = 0;
  GLuint fragment_shader = 0;
  GLuint program = 0;
  GLuint vertex_array = 0;
  GLuint vertex_buffer = 0;
  GLuint reported_buffer = 0;
  GLuint color_texture = 0;
  GLuint depth_texture = 0;
  GLuint framebuffer = 0;

  GlObjects() = default;
  GlObjects(const GlObjects&) = delete;
  GlObjects& operator=(const GlObjects&) = delete;
  ~GlObjects() {
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(1, &depth_texture);
    glDeleteTextures(1, &color_texture);
    glDeleteBuffers(1, &reported_buffer);
    glDeleteBuffers(1, &vertex_buffer);
    glDeleteVertexArrays(1, &vertex_array);
    glDeleteProgram(program);
    glDeleteShader(fragment_shader);
    glDeleteShader(vertex_shader);
  }
};

std::array<float, 16> ToFloat(const Eigen::Matrix4d& matrix) {
  std::array<float, 16> result;
  const Eigen::Matrix4f matrix_float = matrix.cast<float>();  // column-major, like `matrix`
  std::copy(matrix_float.data(), matrix_float.data() + 16, result.begin());
  return result;
}

struct RenderSettings {
  Eigen::Matrix4d clip_from_gl_eye;
  Eigen::Matrix4d gl_eye_from_world;
  ClipDepth clip_depth = ClipDepth::kNegativeOneToOne;
  bool reversed_z = false;
};

// What the GL wrote: per GL pixel (row 0 at the bottom) RGBA and window depth.
struct Readback {
  std::vector<float> rgba;
  std::vector<float> depth;
};

// Draws `triangles` (x, y, z per vertex); the colour of a fragment is `reported` interpolated
// (the same length as `triangles`), or `triangles` itself when `reported` is null.
std::string Render(const std::vector<float>& triangles, const RenderSettings& settings,
                   Readback* readback, const std::vector<float>* reported = nullptr) {
  if (reported != nullptr && reported->size() != triangles.size()) {
    return "reported positions do not match the triangles";
  }
  const int width = kImageSize.width;
  const int height = kImageSize.height;
  GlObjects gl;
  std::string error = CompileShader(GL_VERTEX_SHADER, kVertexShader, &gl.vertex_shader);
  if (error.empty()) {
    error = CompileShader(GL_FRAGMENT_SHADER, kFragmentShader, &gl.fragment_shader);
  }
  if (!error.empty()) return error;
  gl.program = glCreateProgram();
  glAttachShader(gl.program, gl.vertex_shader);
  glAttachShader(gl.program, gl.fragment_shader);
  glLinkProgram(gl.program);
  GLint linked = GL_FALSE;
  glGetProgramiv(gl.program, GL_LINK_STATUS, &linked);
  if (linked != GL_TRUE) {
    char log[2048] = "";
    glGetProgramInfoLog(gl.program, sizeof(log), nullptr, log);
    return std::string("program link failed: ") + log;
  }

  glGenVertexArrays(1, &gl.vertex_array);
  glBindVertexArray(gl.vertex_array);
  glGenBuffers(1, &gl.vertex_buffer);
  glBindBuffer(GL_ARRAY_BUFFER, gl.vertex_buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(triangles.size() * sizeof(float)),
               triangles.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  if (reported != nullptr) {
    glGenBuffers(1, &gl.reported_buffer);
    glBindBuffer(GL_ARRAY_BUFFER, gl.reported_buffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(reported->size() * sizeof(float)),
                 reported->data(), GL_STATIC_DRAW);
  }
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);

  glGenTextures(1, &gl.color_texture);
  glBindTexture(GL_TEXTURE_2D, gl.color_texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
  glGenTextures(1, &gl.depth_texture);
  glBindTexture(GL_TEXTURE_2D, gl.depth_texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, width, height, 0, GL_DEPTH_COMPONENT,
               GL_FLOAT, nullptr);
  for (const GLuint texture : {gl.color_texture, gl.depth_texture}) {
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  glGenFramebuffers(1, &gl.framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, gl.framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, gl.color_texture, 0);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, gl.depth_texture, 0);
  const GLenum draw_buffer = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &draw_buffer);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "framebuffer incomplete: 0x%04X", status);
    return buffer;
  }
  if (error = GlErrorText("creating the GL objects"); !error.empty()) return error;

  // The state a full-image camera render needs, all set explicitly.
  glViewport(0, 0, width, height);
  glDepthRange(0.0, 1.0);
  glClipControl(GL_LOWER_LEFT, settings.clip_depth == ClipDepth::kZeroToOne
                                   ? GL_ZERO_TO_ONE
                                   : GL_NEGATIVE_ONE_TO_ONE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_DEPTH_CLAMP);
  glDisable(GL_MULTISAMPLE);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(settings.reversed_z ? GL_GREATER : GL_LESS);
  const float clear_color[4] = {0.0f, 0.0f, 0.0f, 0.0f};  // alpha 0: not covered
  const float clear_depth = settings.reversed_z ? 0.0f : 1.0f;
  glClearBufferfv(GL_COLOR, 0, clear_color);
  glClearBufferfv(GL_DEPTH, 0, &clear_depth);

  glUseProgram(gl.program);
  const std::array<float, 16> projection = ToFloat(settings.clip_from_gl_eye);
  const std::array<float, 16> view = ToFloat(settings.gl_eye_from_world);
  glUniformMatrix4fv(glGetUniformLocation(gl.program, "u_projection"), 1, GL_FALSE,
                     projection.data());
  glUniformMatrix4fv(glGetUniformLocation(gl.program, "u_view"), 1, GL_FALSE, view.data());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(triangles.size() / 3));
  if (error = GlErrorText("drawing"); !error.empty()) return error;

  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  readback->rgba.assign(static_cast<size_t>(width) * height * 4, -1.0f);
  readback->depth.assign(static_cast<size_t>(width) * height, -1.0f);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, readback->rgba.data());
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, readback->depth.data());
  if (error = GlErrorText("glReadPixels"); !error.empty()) return error;

  // Leave the default clip control for whoever renders next.
  glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glUseProgram(0);
  glBindVertexArray(0);
  return GlErrorText("reading back");
}

// ---------------------------------------------------------------------------------------------
// Scene: an axis-aligned box [-0.5, 0.5]^3 in front of a large tilted background plane.

// A box face: the points with sign * X[axis] = kBoxHalfSize and |X| <= kBoxHalfSize elsewhere.
struct BoxFace {
  int axis = 0;
  double sign = 1.0;
  bool FacesCamera(const Eigen::Vector3d& eye) const { return sign * eye[axis] > kBoxHalfSize; }
};

// +x, +y, +z, -x, -y, -z.
constexpr BoxFace kBoxFaces[6] = {{0, 1.0}, {1, 1.0}, {2, 1.0}, {0, -1.0}, {1, -1.0}, {2, -1.0}};

// The background's unit normal and two unit vectors spanning it.
struct BackgroundFrame {
  Eigen::Vector3d normal = Eigen::Vector3d::Ones().normalized();
  Eigen::Vector3d a = Eigen::Vector3d(1.0, -1.0, 0.0).normalized();
  Eigen::Vector3d b = normal.cross(a);
};

// Two triangles; corners in order around the quad.
void AppendQuad(const std::array<Eigen::Vector3d, 4>& corners,
                std::vector<Eigen::Vector3d>* triangles) {
  for (const int index : {0, 1, 2, 0, 2, 3}) triangles->push_back(corners[index]);
}

// The vertices as the float32 array GL takes.
std::vector<float> ToFloatVertices(const std::vector<Eigen::Vector3d>& vertices) {
  std::vector<float> result;
  result.reserve(3 * vertices.size());
  for (const Eigen::Vector3d& vertex : vertices) {
    for (int k = 0; k < 3; ++k) result.push_back(static_cast<float>(vertex[k]));
  }
  return result;
}

// Box faces in kBoxFaces order (the camera-facing ones first, so that a missing depth test
// shows), then the background last (so that it would overwrite everything without one); in
// double, three vertices per triangle.
std::vector<Eigen::Vector3d> SceneTrianglesInWorld() {
  std::vector<Eigen::Vector3d> triangles;
  for (const BoxFace& face : kBoxFaces) {
    const Eigen::Vector3d center = face.sign * kBoxHalfSize * Eigen::Vector3d::Unit(face.axis);
    const Eigen::Vector3d a = kBoxHalfSize * Eigen::Vector3d::Unit((face.axis + 1) % 3);
    const Eigen::Vector3d b = kBoxHalfSize * Eigen::Vector3d::Unit((face.axis + 2) % 3);
    AppendQuad({center - a - b, center + a - b, center + a + b, center - a + b}, &triangles);
  }
  // The background as a grid of small quads rather than two huge triangles. Big triangles that
  // cross the image border get clipped by the driver into thin slivers whose float plane
  // equations extrapolate badly along their long edge: measured max errors were 5e-4 px with a
  // single quad (llvmpipe) and 6.4e-4 px with 8 x 8 quads (softpipe), against <= 4e-5 px with
  // 32 x 32 on both. That is driver arithmetic, not the matrices, so the scene avoids it. Each
  // lattice vertex is computed once, so neighbouring quads share exact float corners (no cracks).
  const BackgroundFrame frame;
  const auto vertex = [&](int row, int column) -> Eigen::Vector3d {
    const double s = (2.0 * column / kBackgroundGrid - 1.0) * kBackgroundHalfSize;
    const double t = (2.0 * row / kBackgroundGrid - 1.0) * kBackgroundHalfSize;
    return kBackgroundOffset * frame.normal + s * frame.a + t * frame.b;
  };
  for (int row = 0; row < kBackgroundGrid; ++row) {
    for (int column = 0; column < kBackgroundGrid; ++column) {
      AppendQuad({vertex(row, column), vertex(row, column + 1), vertex(row + 1, column + 1),
                  vertex(row + 1, column)},
                 &triangles);
    }
  }
  return triangles;
}

std::vector<float> SceneTriangles() { return ToFloatVertices(SceneTrianglesInWorld()); }

enum Surface { kFrontFace, kBackFace, kBackground, kNoSurface };

// Which scene surface `point` lies on, as seen from a camera at `eye`; *face_index is the index
// in kBoxFaces for a box face. Plain arithmetic: this runs for every pixel, also in -O0 builds.
Surface Classify(const Eigen::Vector3d& point, const Eigen::Vector3d& eye,
                 const BackgroundFrame& frame, int* face_index) {
  *face_index = -1;
  const double p[3] = {point.x(), point.y(), point.z()};
  const double limit = kBoxHalfSize + kOnPlaneTolerance;
  const bool in_box = std::abs(p[0]) <= limit && std::abs(p[1]) <= limit && std::abs(p[2]) <= limit;
  if (in_box) {
    for (const bool want_front : {true, false}) {  // an edge point counts for its front face
      for (int i = 0; i < 6; ++i) {
        const BoxFace& face = kBoxFaces[i];
        if (face.FacesCamera(eye) != want_front) continue;
        if (std::abs(face.sign * p[face.axis] - kBoxHalfSize) <= kOnPlaneTolerance) {
          *face_index = i;
          return want_front ? kFrontFace : kBackFace;
        }
      }
    }
  }
  const auto dot = [&p](const Eigen::Vector3d& v) {
    return p[0] * v[0] + p[1] * v[1] + p[2] * v[2];
  };
  if (std::abs(dot(frame.normal) - kBackgroundOffset) <= kOnPlaneTolerance &&
      std::abs(dot(frame.a)) <= kBackgroundHalfSize + kOnPlaneTolerance &&
      std::abs(dot(frame.b)) <= kBackgroundHalfSize + kOnPlaneTolerance) {
    return kBackground;
  }
  return kNoSurface;
}

// ---------------------------------------------------------------------------------------------
// Test cases.

struct CameraCase {
  const char* name;
  Intrinsics intrinsics;  // kCenter
  LookAt look_at;
  Projection projection = Projection::kPerspective;
};

CameraCase Centered() {
  CameraCase camera{"Centered", {}, {}};
  camera.intrinsics.fx = 150.0;
  camera.intrinsics.fy = 150.0;
  camera.intrinsics.cx = (kImageSize.width - 1) / 2.0;
  camera.intrinsics.cy = (kImageSize.height - 1) / 2.0;
  camera.look_at.eye = Eigen::Vector3d(3.0, 2.0, 2.6);
  camera.look_at.target = Eigen::Vector3d(0.1, -0.1, 0.05);
  camera.look_at.up = Eigen::Vector3d(0.15, 1.0, -0.1);  // some roll
  return camera;
}

// Projector-like: the principal point on the bottom row, so the image sees only above the axis.
CameraCase Projector() {
  CameraCase camera{"Projector", {}, {}};
  camera.intrinsics.fx = 170.0;
  camera.intrinsics.fy = 140.0;
  camera.intrinsics.cx = 87.25;
  camera.intrinsics.cy = kImageSize.height - 1.0;
  camera.look_at.eye = Eigen::Vector3d(2.4, 1.2, 3.4);
  camera.look_at.target = Eigen::Vector3d(0.0, -1.1, 0.0);
  camera.look_at.up = Eigen::Vector3d(-0.1, 1.0, 0.05);
  return camera;
}

CameraCase Skewed() {
  CameraCase camera{"Skewed", {}, {}};
  camera.intrinsics.fx = 150.0;
  camera.intrinsics.fy = 156.0;
  camera.intrinsics.skew = 15.0;
  camera.intrinsics.cx = 70.3;
  camera.intrinsics.cy = 52.8;
  camera.look_at.eye = Eigen::Vector3d(3.3, 1.6, 2.2);
  camera.look_at.target = Eigen::Vector3d(-0.1, 0.1, 0.0);
  camera.look_at.up = Eigen::Vector3d(0.0, 1.0, 0.2);
  return camera;
}

// Orthographic with skew and an off-centre axis: 36 px per world unit shows a 4.4 x 3.3 window
// of the scene; the eye sits 4.7 units from the box, in front of everything it sees.
CameraCase Orthographic() {
  CameraCase camera{"Orthographic", {}, {}, Projection::kOrthographic};
  camera.intrinsics.fx = 36.0;
  camera.intrinsics.fy = 37.5;
  camera.intrinsics.skew = 3.0;
  camera.intrinsics.cx = 83.2;
  camera.intrinsics.cy = 55.7;
  camera.look_at.eye = Eigen::Vector3d(3.0, 2.0, 2.6);
  camera.look_at.target = Eigen::Vector3d(0.1, -0.1, 0.05);
  camera.look_at.up = Eigen::Vector3d(0.15, 1.0, -0.1);
  return camera;
}

// The pixel of a point in cam under the case's projection (double precision, from
// camera.h's definitions, not from the GL matrices).
Eigen::Vector2d ExpectedPixel(const CameraCase& camera, const Eigen::Vector3d& point_in_cam) {
  const Intrinsics& k = camera.intrinsics;
  if (camera.projection == Projection::kOrthographic) {
    return {k.fx * point_in_cam.x() + k.skew * point_in_cam.y() + k.cx,
            k.fy * point_in_cam.y() + k.cy};
  }
  return PixelFromCam(k, point_in_cam);
}

struct DepthCase {
  const char* name;
  GlDepth depth;
};

// Readable parameters in test failures instead of byte dumps.
void PrintTo(const CameraCase& camera, std::ostream* os) { *os << camera.name; }
void PrintTo(const DepthCase& depth, std::ostream* os) { *os << depth.name; }

using RenderParam = std::tuple<CameraCase, DepthCase>;

// The window depth the pinhole model predicts at cam-frame depth z (> 0) for glDepthRange(0, 1),
// from first principles rather than from the projection matrix: both NO and ZO map z = n to 0 and
// z = f to 1 hyperbolically, i.e. f (z - n) / ((f - n) z); reversed-Z is 1 minus that.
// Orthographic: linear, (z - n) / (f - n).
double ExpectedWindowDepth(double z, bool reversed_z, Projection projection) {
  const double n = kZNear;
  const double f = kZFar;
  if (projection == Projection::kOrthographic) {
    return reversed_z ? (f - z) / (f - n) : (z - n) / (f - n);
  }
  return reversed_z ? n * (f - z) / ((f - n) * z) : f * (z - n) / ((f - n) * z);
}

// A test fixture (Base: testing::Test or TestWithParam) with a headless GL context per suite.
template <typename Base>
class WithHeadlessGl : public Base {
 protected:
  static void SetUpTestSuite() {
    context_ = HeadlessGlContext::Create(&skip_reason_).release();
    if (context_ != nullptr) {
      std::printf("[ render   ] %s\n", context_->description().c_str());
    }
  }
  static void TearDownTestSuite() {
    delete context_;
    context_ = nullptr;
  }
  // Without a context each case is skipped with the reason -- unless CAMPROJ_REQUIRE_GL=1 (set
  // by .ci/run): CI must not go green without the render proof.
  void SetUp() override {
    if (context_ != nullptr) return;
    const char* require = std::getenv("CAMPROJ_REQUIRE_GL");
    if (require != nullptr && std::string(require) == "1") {
      FAIL() << "CAMPROJ_REQUIRE_GL=1 but there is no headless OpenGL: " << skip_reason_;
    }
    GTEST_SKIP() << "no headless OpenGL: " << skip_reason_;
  }

  static inline HeadlessGlContext* context_ = nullptr;
  static inline std::string skip_reason_;
};

class RenderTest : public WithHeadlessGl<testing::TestWithParam<RenderParam>> {};

TEST_P(RenderTest, PointsProjectOntoTheirPixelsWithTheExpectedDepth) {
  const auto& [camera, depth_case] = GetParam();
  const Rigid3 cam_from_world = CamFromWorldFromLookAt(camera.look_at);
  RenderSettings settings;
  settings.clip_from_gl_eye =
      camera.projection == Projection::kOrthographic
          ? ClipFromGlEyeOrthographic(camera.intrinsics, kImageSize, kZNear, kZFar, depth_case.depth)
          : ClipFromGlEye(camera.intrinsics, kImageSize, kZNear, kZFar, depth_case.depth);
  settings.gl_eye_from_world = GlEyeFromWorld(cam_from_world);
  settings.clip_depth = depth_case.depth.clip_depth;
  settings.reversed_z = depth_case.depth.reversed_z;

  Readback readback;
  const std::string error = Render(SceneTriangles(), settings, &readback);
  ASSERT_TRUE(error.empty()) << error;

  const int width = kImageSize.width;
  const int height = kImageSize.height;
  const BackgroundFrame background_frame;
  int covered = 0;
  int not_in_scene = 0;
  double max_pixel_error = 0.0;
  double max_depth_error = 0.0;
  Eigen::Vector2d worst_pixel(-1.0, -1.0);
  Eigen::Vector2d worst_projection(-1.0, -1.0);
  std::array<int, 6> face_pixels{};
  int background_pixels = 0;
  for (int j = 0; j < height; ++j) {
    for (int i = 0; i < width; ++i) {
      const size_t index = static_cast<size_t>(j) * width + i;
      const float* rgba = &readback.rgba[4 * index];
      if (rgba[3] != 1.0f) {
        ASSERT_EQ(rgba[3], 0.0f) << "at GL pixel (" << i << ", " << j << ")";
        continue;
      }
      ++covered;
      const Eigen::Vector3d point_in_world(rgba[0], rgba[1], rgba[2]);
      const Eigen::Vector3d point_in_cam = cam_from_world * point_in_world;
      const Eigen::Vector2d pixel(i, height - 1 - j);  // see the file comment
      const Eigen::Vector2d projection = ExpectedPixel(camera, point_in_cam);
      const double pixel_error = (projection - pixel).norm();
      if (!(pixel_error <= max_pixel_error)) {  // also keeps a NaN
        max_pixel_error = pixel_error;
        worst_pixel = pixel;
        worst_projection = projection;
      }
      const double expected_depth =
          ExpectedWindowDepth(point_in_cam.z(), depth_case.depth.reversed_z, camera.projection);
      max_depth_error = std::max(max_depth_error, std::abs(readback.depth[index] - expected_depth));

      int face_index = -1;
      switch (Classify(point_in_world, camera.look_at.eye, background_frame, &face_index)) {
        case kFrontFace:
          ++face_pixels[face_index];
          break;
        case kBackFace:
          ADD_FAILURE() << "a face turned away from the camera is visible at image pixel "
                        << pixel.transpose() << ": the depth test is not working";
          break;
        case kBackground:
          ++background_pixels;
          break;
        case kNoSurface:
          ++not_in_scene;
          break;
      }
    }
  }

  const double covered_fraction = static_cast<double>(covered) / (width * height);
  std::printf("[ render   ] %s/%s: covered %.4f, max pixel error %.3g px, max depth error %.3g\n",
              camera.name, depth_case.name, covered_fraction, max_pixel_error, max_depth_error);
  RecordProperty("max_pixel_error", std::to_string(max_pixel_error));
  RecordProperty("max_depth_error", std::to_string(max_depth_error));

  EXPECT_GE(covered_fraction, kMinCoveredFraction);
  EXPECT_LE(max_pixel_error, kMaxPixelError)
      << "image pixel " << worst_pixel.transpose() << " holds a world point that K [R|t] puts at "
      << worst_projection.transpose();
  EXPECT_LE(max_depth_error, kMaxDepthError);
  EXPECT_EQ(not_in_scene, 0) << "pixels whose read-back point lies on no scene surface";
  EXPECT_GE(background_pixels, kMinPixelsPerSurface);
  int front_faces = 0;
  for (int i = 0; i < 6; ++i) {
    if (!kBoxFaces[i].FacesCamera(camera.look_at.eye)) continue;  // for the ortho case too:
                                                                   // its eye sees the same faces
    ++front_faces;
    EXPECT_GE(face_pixels[i], kMinPixelsPerSurface) << "box face " << i;
  }
  EXPECT_EQ(front_faces, 3) << "the box should show three non-coplanar faces";
}

std::string ParamName(const testing::TestParamInfo<RenderParam>& info) {
  return std::string(std::get<0>(info.param).name) + "_" + std::get<1>(info.param).name;
}

INSTANTIATE_TEST_SUITE_P(
    CamerasAndDepths, RenderTest,
    testing::Combine(testing::Values(Centered(), Projector(), Skewed(), Orthographic()),
                     testing::Values(DepthCase{"NegativeOneToOne",
                                               {ClipDepth::kNegativeOneToOne, false}},
                                     DepthCase{"ZeroToOne", {ClipDepth::kZeroToOne, false}},
                                     DepthCase{"ZeroToOneReversed", {ClipDepth::kZeroToOne, true}},
                                     DepthCase{"NegativeOneToOneReversed",
                                               {ClipDepth::kNegativeOneToOne, true}})),
    ParamName);

// ---------------------------------------------------------------------------------------------
// Survey-scale coordinates in float32 (docs/conventions.md, section 11): the Centered case scaled
// to metres (a 10 m box, the camera ~40 m away, the background 240 m wide) and moved to UTM-like
// coordinates, where float32's spacing is 2^-5 m in E (~4e5) and 0.5 m in N (~5.6e6).

constexpr double kSurveyScale = 10.0;

Eigen::Vector3d SurveyOffset() { return {412345.678, 5612345.678, 123.456}; }

// What a survey-scale render gives: the worst distance between a covered pixel's centre and where
// K [R|t] (double, absolute world) puts the exact scene point read back there.
struct SurveyRender {
  double covered_fraction = 0.0;
  double max_pixel_error = 0.0;
  double depth_of_worst = 0.0;  // cam depth of the worst pixel's point
};

class SurveyScaleRenderTest : public WithHeadlessGl<testing::Test> {
 protected:
  // The camera of the Centered case, scaled and moved with the scene.
  static Camera SurveyCamera() {
    const CameraCase base = Centered();
    LookAt look_at = base.look_at;
    look_at.eye = SurveyOffset() + kSurveyScale * base.look_at.eye;
    look_at.target = SurveyOffset() + kSurveyScale * base.look_at.target;
    Camera camera;
    camera.image_size = kImageSize;
    camera.intrinsics = base.intrinsics;
    camera.cam_from_world = CamFromWorldFromLookAt(look_at);
    camera.z_near = kSurveyScale * kZNear;
    camera.z_far = kSurveyScale * kZFar;
    return camera;
  }

  // Draws `vertices_for_gl` (float32, as the GL user would give them) with `view` and reports the
  // exact scene point of each fragment: the double scene relative to SurveyOffset(), cast to
  // float (|X| <= ~170 m: float32 keeps it to ~1e-5 m, 5e-5 px at 30 m), plus the offset in double.
  static SurveyRender Measure(const Camera& camera, const std::vector<float>& vertices_for_gl,
                              const Eigen::Matrix4d& view,
                              const std::vector<Eigen::Vector3d>& scene_in_world,
                              std::string* error) {
    std::vector<Eigen::Vector3d> scene_from_offset;
    for (const Eigen::Vector3d& vertex : scene_in_world) {
      scene_from_offset.push_back(vertex - SurveyOffset());
    }
    const std::vector<float> reported = ToFloatVertices(scene_from_offset);
    RenderSettings settings;
    settings.clip_from_gl_eye =
        ClipFromGlEye(camera.intrinsics, kImageSize, camera.z_near, camera.z_far);
    settings.gl_eye_from_world = view;
    Readback readback;
    *error = Render(vertices_for_gl, settings, &readback, &reported);
    SurveyRender result;
    if (!error->empty()) return result;
    const int width = kImageSize.width;
    const int height = kImageSize.height;
    int covered = 0;
    for (int j = 0; j < height; ++j) {
      for (int i = 0; i < width; ++i) {
        const size_t index = static_cast<size_t>(j) * width + i;
        const float* rgba = &readback.rgba[4 * index];
        if (rgba[3] != 1.0f) continue;
        ++covered;
        const Eigen::Vector3d point_in_world =
            SurveyOffset() + Eigen::Vector3d(rgba[0], rgba[1], rgba[2]);
        const Eigen::Vector3d point_in_cam = camera.cam_from_world * point_in_world;
        const Eigen::Vector2d pixel(i, height - 1 - j);  // see the file comment
        const double pixel_error = (PixelFromCam(camera.intrinsics, point_in_cam) - pixel).norm();
        if (!(pixel_error <= result.max_pixel_error)) {  // also keeps a NaN
          result.max_pixel_error = pixel_error;
          result.depth_of_worst = point_in_cam.z();
        }
      }
    }
    result.covered_fraction = static_cast<double>(covered) / (width * height);
    return result;
  }
};

// Raw survey coordinates in float32 put the scene pixels away from where the camera sees it;
// vertices relative to the automatic world origin (the scene's centroid rounded) and the view
// matrix gl_eye_from_origin_world bring it back within the 1e-3 px of the unit-scale render.
// Measured (llvmpipe): 3.06 px without the origin (Float32PixelError at that depth: 4.2 px),
// 2.7e-5 px with it (Float32PixelError: 7.6e-5 px).
TEST_F(SurveyScaleRenderTest, Float32SurveyCoordinatesNeedTheWorldOrigin) {
  const Camera camera = SurveyCamera();
  std::vector<Eigen::Vector3d> scene_in_world = SceneTrianglesInWorld();
  for (Eigen::Vector3d& vertex : scene_in_world) vertex = SurveyOffset() + kSurveyScale * vertex;

  // Without an origin: the vertices as float32 world coordinates, the plain view matrix.
  std::string error;
  const SurveyRender without = Measure(camera, ToFloatVertices(scene_in_world),
                                       GlEyeFromWorld(camera.cam_from_world), scene_in_world, &error);
  ASSERT_TRUE(error.empty()) << error;

  // With the origin: point_in_world - origin subtracted in double, then cast.
  const Eigen::Vector3d origin = AutoOriginOfPoints(scene_in_world);
  std::vector<Eigen::Vector3d> scene_from_origin;
  for (const Eigen::Vector3d& vertex : scene_in_world) scene_from_origin.push_back(vertex - origin);
  const SurveyRender with = Measure(camera, ToFloatVertices(scene_from_origin),
                                    GlEyeFromOriginWorld(camera.cam_from_world, origin),
                                    scene_in_world, &error);
  ASSERT_TRUE(error.empty()) << error;

  const double expected_without = Float32PixelError(camera, std::nullopt, without.depth_of_worst);
  const double expected_with = Float32PixelError(camera, origin, with.depth_of_worst);
  std::printf("[ render   ] survey scale, origin (%.17g, %.17g, %.17g): max pixel error %.3g px "
              "without the origin (expected %.3g px at depth %.4g), %.3g px with it (expected "
              "%.3g px)\n",
              origin.x(), origin.y(), origin.z(), without.max_pixel_error, expected_without,
              without.depth_of_worst, with.max_pixel_error, expected_with);
  RecordProperty("max_pixel_error_without_origin", std::to_string(without.max_pixel_error));
  RecordProperty("max_pixel_error_with_origin", std::to_string(with.max_pixel_error));

  // The auto rule: the scene's extent is 240 m (the background), so step 100.
  EXPECT_EQ(origin, Eigen::Vector3d(412300.0, 5612300.0, 100.0));
  EXPECT_GE(without.covered_fraction, kMinCoveredFraction);
  EXPECT_GE(with.covered_fraction, kMinCoveredFraction);
  // The problem is real: above the level at which camproj export warns.
  EXPECT_GT(without.max_pixel_error, kFloat32ErrorWarningPx);
  // And the size the export prints is right to an order of magnitude: Float32PixelError sums
  // per-operation rounding bounds with constants of order 1 (world_origin.cc); the worst of
  // ~19000 pixels reaches a fraction of order 1 of it, neither 10x less nor 10x more.
  EXPECT_GT(without.max_pixel_error, expected_without / 10.0);
  EXPECT_LT(without.max_pixel_error, expected_without * 10.0);
  // With the origin: the unit-scale render's budget (kMaxPixelError), which the issue asks for.
  EXPECT_LE(with.max_pixel_error, kMaxPixelError);
}

}  // namespace
}  // namespace camproj
