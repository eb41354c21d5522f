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
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "camproj/conventions.h"
#include "camproj/gl.h"
#include "camproj/camera.h"
#include "camproj/intrinsics.h"
#include "camproj/lens_gl.h"
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
constexpr int kBackgroundGrid = 32;  // quads per side; see TessellatedSceneInWorld()

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
// shows), each split into box_cells^2 quads, then the background last (so that it would
// overwrite everything without one), split into background_cells^2; either may be left out (0
// cells). In double, three vertices per triangle.
//
// The background is a grid of small quads rather than two huge triangles. Big triangles that
// cross the image border get clipped by the driver into thin slivers whose float plane
// equations extrapolate badly along their long edge: measured max errors were 5e-4 px with a
// single quad (llvmpipe) and 6.4e-4 px with 8 x 8 quads (softpipe), against <= 4e-5 px with
// 32 x 32 on both. That is driver arithmetic, not the matrices, so the scene avoids it. Each
// lattice vertex is computed once, so neighbouring quads share exact float corners (no cracks).
std::vector<Eigen::Vector3d> TessellatedSceneInWorld(int box_cells, int background_cells) {
  std::vector<Eigen::Vector3d> triangles;
  for (int f = 0; f < 6 && box_cells > 0; ++f) {
    const BoxFace& face = kBoxFaces[f];
    const Eigen::Vector3d center = face.sign * kBoxHalfSize * Eigen::Vector3d::Unit(face.axis);
    const Eigen::Vector3d a = kBoxHalfSize * Eigen::Vector3d::Unit((face.axis + 1) % 3);
    const Eigen::Vector3d b = kBoxHalfSize * Eigen::Vector3d::Unit((face.axis + 2) % 3);
    const auto vertex = [&](int row, int column) -> Eigen::Vector3d {
      return center + (2.0 * column / box_cells - 1.0) * a + (2.0 * row / box_cells - 1.0) * b;
    };
    for (int row = 0; row < box_cells; ++row) {
      for (int column = 0; column < box_cells; ++column) {
        AppendQuad({vertex(row, column), vertex(row, column + 1), vertex(row + 1, column + 1),
                    vertex(row + 1, column)},
                   &triangles);
      }
    }
  }
  const BackgroundFrame frame;
  const auto vertex = [&](int row, int column) -> Eigen::Vector3d {
    const double s = (2.0 * column / background_cells - 1.0) * kBackgroundHalfSize;
    const double t = (2.0 * row / background_cells - 1.0) * kBackgroundHalfSize;
    return kBackgroundOffset * frame.normal + s * frame.a + t * frame.b;
  };
  for (int row = 0; row < background_cells; ++row) {
    for (int column = 0; column < background_cells; ++column) {
      AppendQuad({vertex(row, column), vertex(row, column + 1), vertex(row + 1, column + 1),
                  vertex(row + 1, column)},
                 &triangles);
    }
  }
  return triangles;
}

// The render test's scene: one quad per box face (its corners exactly center -+ a -+ b) and the
// 32 x 32 background.
std::vector<Eigen::Vector3d> SceneTrianglesInWorld() {
  return TessellatedSceneInWorld(1, kBackgroundGrid);
}

std::vector<float> TessellatedScene(int box_cells, int background_cells) {
  return ToFloatVertices(TessellatedSceneInWorld(box_cells, background_cells));
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

// The lens tests below use the unparameterized fixture under this name.
using GlTest = WithHeadlessGl<testing::Test>;

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
// The lens (lens_gl.h): k1, k2 rendered three ways, each checked as above against
// PixelFromWorld, which applies the distortion in double. Lens cases of both signs of k1 and k2,
// two of them with the first fold just outside the image (the image corners at 95 % of the
// fold's distorted radius).

// Interior error target for the per-vertex lens: the scene is tessellated by the docs' rule
// (longest edge <= LensMaxEdgePx(camera, target)); the bound M L^2 / 6 then holds at every pixel,
// plus the float budget kMaxPixelError.
constexpr double kTessellationTargetPx = 0.01;

// The issue's bound for a post-process warp (bilinear sampling of the pinhole render target) on a
// smooth scene. What it allows for: the map's own interpolation (the STMap is exact per pixel,
// the mesh within kLensMeshErrorPx = 0.01 px), bilinear interpolation of a projective map
// (world position against pixel on a plane: |X''| h^2 / 8 with h = 1 texel, ~1e-5 px here) and
// the sampler's fixed-point weights (GPUs use 8 bits: 1/512 texel, ~2e-3 px, times the lens
// scale <= ~1.5). The undistortion samples the plate, where world position against pixel is bent
// by the lens: bilinear interpolation then errs by |U''| h^2 / 8 (U = the inverse lens map, in
// px, h = 1 texel), which grows without bound towards the fold: ~0.3 px^-1 at the corners of the
// near-fold cases here, i.e. ~0.04 px. Measured (llvmpipe): STMap <= 2.9e-4 px, mesh <= 9.6e-3
// px (its own interpolation error, <= kLensMeshErrorPx), undistortion <= 0.033 px (near the fold;
// 7.5e-4 px for the pincushion).
constexpr double kMaxWarpErrorPx = 0.05;

struct LensCase {
  const char* name;
  Intrinsics intrinsics;  // kCenter
};

void PrintTo(const LensCase& lens, std::ostream* os) { *os << lens.name; }

LensCase Lens(const char* name, double fx, double fy, double cx, double cy, double skew, double k1,
              double k2) {
  LensCase lens{name, {}};
  lens.intrinsics.fx = fx;
  lens.intrinsics.fy = fy;
  lens.intrinsics.cx = cx;
  lens.intrinsics.cy = cy;
  lens.intrinsics.skew = skew;
  lens.intrinsics.k1 = k1;
  lens.intrinsics.k2 = k2;
  return lens;
}

// Image corners at distorted normalized radius 0.667: k1 = -0.3 folds at r = 1.054 (distorted
// 0.703), k1 = -0.35, k2 = 0.04 at r = 1.118 (distorted 0.699), k1 = 0.1, k2 = -0.3 at r = 0.961
// (distorted 0.804); k1 = 0.25, k2 = 0.08 never folds.
const LensCase kLensCases[] = {
    Lens("BarrelNearFold", 150.0, 150.0, 79.5, 59.5, 0.0, -0.3, 0.0),
    Lens("BarrelPositiveK2NearFold", 150.0, 150.0, 79.5, 59.5, 0.0, -0.35, 0.04),
    Lens("Pincushion", 150.0, 156.0, 83.1, 57.4, 0.0, 0.25, 0.08),
    Lens("PincushionNegativeK2Skewed", 150.0, 145.0, 77.2, 62.9, 8.0, 0.1, -0.3),
};

Camera LensCamera(const LensCase& lens) {
  Camera camera;
  camera.image_size = kImageSize;
  camera.intrinsics = lens.intrinsics;
  LookAt look_at;
  look_at.eye = Eigen::Vector3d(3.0, 2.0, 2.6);
  look_at.target = Eigen::Vector3d(0.1, -0.1, 0.05);
  look_at.up = Eigen::Vector3d(0.15, 1.0, -0.1);
  camera.cam_from_world = CamFromWorldFromLookAt(look_at);
  camera.z_near = kZNear;
  camera.z_far = kZFar;
  return camera;
}


// The longest triangle edge on the camera's pinhole image (px) among triangles with a vertex in
// the lens render target's view (which holds the image's footprint); infinity if such a triangle
// reaches behind the camera.
double LongestVisibleEdgePx(const std::vector<float>& triangles, const Camera& camera) {
  const LensRenderTarget target = LensRenderTargetOf(camera);
  double longest = 0.0;
  for (size_t t = 0; t + 9 <= triangles.size(); t += 9) {
    std::array<Eigen::Vector2d, 3> pixels;
    bool visible = false;
    bool behind = false;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d point_in_world(triangles[t + 3 * i], triangles[t + 3 * i + 1],
                                           triangles[t + 3 * i + 2]);
      const Eigen::Vector3d point_in_cam = camera.cam_from_world * point_in_world;
      if (point_in_cam.z() <= 0.0) {
        behind = true;
        continue;
      }
      pixels[i] = PixelFromCam(target.intrinsics, point_in_cam);
      visible = visible || (pixels[i].x() >= -0.5 && pixels[i].x() <= target.size.width - 0.5 &&
                            pixels[i].y() >= -0.5 && pixels[i].y() <= target.size.height - 0.5);
    }
    if (!visible) continue;
    if (behind) return std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i)
      longest = std::max(longest, (pixels[i] - pixels[(i + 1) % 3]).norm());
  }
  return longest;
}

// The smallest number of cells (from `cells` up) whose scene has every visible edge <= max_edge.
template <typename MakeScene>
int CellsForEdge(int cells, double max_edge_px, const Camera& camera, MakeScene make_scene) {
  for (;;) {
    const double longest = LongestVisibleEdgePx(make_scene(cells), camera);
    if (longest <= max_edge_px) return cells;
    cells = static_cast<int>(std::ceil(cells * std::max(1.1, 1.02 * longest / max_edge_px)));
  }
}

std::string LinkProgram(GLuint program) {
  glLinkProgram(program);
  GLint linked = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  if (linked == GL_TRUE) return "";
  char log[2048] = "";
  glGetProgramInfoLog(program, sizeof(log), nullptr, log);
  return std::string("program link failed: ") + log;
}

// Vertex and fragment shader linked into gl->program; with `feedback`, that varying is captured
// by transform feedback (and the fragment shader may be null).
std::string BuildProgram(const std::string& vertex_source, const char* fragment_source,
                         GlObjects* gl, const char* feedback = nullptr) {
  std::string error = CompileShader(GL_VERTEX_SHADER, vertex_source.c_str(), &gl->vertex_shader);
  if (error.empty() && fragment_source != nullptr) {
    error = CompileShader(GL_FRAGMENT_SHADER, fragment_source, &gl->fragment_shader);
  }
  if (!error.empty()) return error;
  gl->program = glCreateProgram();
  glAttachShader(gl->program, gl->vertex_shader);
  if (fragment_source != nullptr) glAttachShader(gl->program, gl->fragment_shader);
  if (feedback != nullptr) {
    glTransformFeedbackVaryings(gl->program, 1, &feedback, GL_INTERLEAVED_ATTRIBS);
  }
  return LinkProgram(gl->program);
}

// Input textures of a pass, deleted with it.
struct GlTextures {
  std::vector<GLuint> ids;
  GlTextures() = default;
  GlTextures(const GlTextures&) = delete;
  GlTextures& operator=(const GlTextures&) = delete;
  ~GlTextures() {
    if (!ids.empty()) glDeleteTextures(static_cast<GLsizei>(ids.size()), ids.data());
  }
  // An RGBA32F texture of `rgba` (row 0 = the bottom row, as GL stores textures), filtered
  // bilinearly (GL_LINEAR, no mipmaps) and clamped to its edge.
  GLuint Upload(int width, int height, const std::vector<float>& rgba) {
    GLuint id = 0;
    glGenTextures(1, &id);
    ids.push_back(id);
    glBindTexture(GL_TEXTURE_2D, id);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, rgba.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    return id;
  }
};

// Rows of an image stored top row first (image files, StMap) in GL's order, bottom row first.
std::vector<float> BottomRowFirst(int width, int height, const std::vector<float>& rgba) {
  std::vector<float> flipped(rgba.size());
  const size_t row = static_cast<size_t>(width) * 4;
  for (int y = 0; y < height; ++y) {
    std::copy(rgba.begin() + y * row, rgba.begin() + (y + 1) * row,
              flipped.begin() + (height - 1 - y) * row);
  }
  return flipped;
}

// A width x height framebuffer (RGBA32F colour cleared to 0, DEPTH32F depth) made current with
// the full viewport and the depth state of `depth`.
std::string BindFramebuffer(int width, int height, const GlDepth& depth, GlObjects* gl) {
  glGenTextures(1, &gl->color_texture);
  glBindTexture(GL_TEXTURE_2D, gl->color_texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
  glGenTextures(1, &gl->depth_texture);
  glBindTexture(GL_TEXTURE_2D, gl->depth_texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, width, height, 0, GL_DEPTH_COMPONENT,
               GL_FLOAT, nullptr);
  for (const GLuint texture : {gl->color_texture, gl->depth_texture}) {
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  glGenFramebuffers(1, &gl->framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, gl->framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, gl->color_texture, 0);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, gl->depth_texture, 0);
  const GLenum draw_buffer = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &draw_buffer);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "framebuffer incomplete: 0x%04X", status);
    return buffer;
  }
  glViewport(0, 0, width, height);
  glDepthRange(0.0, 1.0);
  glClipControl(GL_LOWER_LEFT, depth.clip_depth == ClipDepth::kZeroToOne ? GL_ZERO_TO_ONE
                                                                         : GL_NEGATIVE_ONE_TO_ONE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_DEPTH_CLAMP);
  glDisable(GL_MULTISAMPLE);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(depth.reversed_z ? GL_GREATER : GL_LESS);
  const float clear_color[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  const float clear_depth = depth.reversed_z ? 0.0f : 1.0f;
  glClearBufferfv(GL_COLOR, 0, clear_color);
  glClearBufferfv(GL_DEPTH, 0, &clear_depth);
  return GlErrorText("creating the framebuffer");
}

std::string ReadFramebuffer(int width, int height, Readback* readback) {
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  readback->rgba.assign(static_cast<size_t>(width) * height * 4, -1.0f);
  readback->depth.assign(static_cast<size_t>(width) * height, -1.0f);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, readback->rgba.data());
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, readback->depth.data());
  std::string error = GlErrorText("glReadPixels");
  glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glUseProgram(0);
  glBindVertexArray(0);
  return error.empty() ? GlErrorText("reading back") : error;
}

// Uploads vec3 triangles as attributes 0 (drawn) and 1 (reported: kVertexShader writes it back)
// of a new vertex array.
void UploadTriangles(const std::vector<float>& triangles, GlObjects* gl) {
  glGenVertexArrays(1, &gl->vertex_array);
  glBindVertexArray(gl->vertex_array);
  glGenBuffers(1, &gl->vertex_buffer);
  glBindBuffer(GL_ARRAY_BUFFER, gl->vertex_buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(triangles.size() * sizeof(float)),
               triangles.data(), GL_STATIC_DRAW);
  for (const GLuint attribute : {0u, 1u}) {
    glEnableVertexAttribArray(attribute);
    glVertexAttribPointer(attribute, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  }
}

// Draws world-position triangles with `vertex_source` (which writes v_world_position) into a
// width x height framebuffer; u_projection and u_view are set where the shader has them.
std::string RenderWorldPositions(const std::string& vertex_source,
                                 const std::vector<float>& triangles, int width, int height,
                                 const Eigen::Matrix4d& clip_from_gl_eye,
                                 const Eigen::Matrix4d& gl_eye_from_world, const GlDepth& depth,
                                 Readback* readback) {
  GlObjects gl;
  std::string error = BuildProgram(vertex_source, kFragmentShader, &gl);
  if (!error.empty()) return error;
  UploadTriangles(triangles, &gl);
  if (error = BindFramebuffer(width, height, depth, &gl); !error.empty()) return error;
  glUseProgram(gl.program);
  const std::array<float, 16> projection = ToFloat(clip_from_gl_eye);
  const std::array<float, 16> view = ToFloat(gl_eye_from_world);
  glUniformMatrix4fv(glGetUniformLocation(gl.program, "u_projection"), 1, GL_FALSE,
                     projection.data());
  glUniformMatrix4fv(glGetUniformLocation(gl.program, "u_view"), 1, GL_FALSE, view.data());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(triangles.size() / 3));
  if (error = GlErrorText("drawing"); !error.empty()) return error;
  return ReadFramebuffer(width, height, readback);
}

// gl_Position of every vertex as the GL computes it (transform feedback, rasterizer off).
std::string CaptureClipPositions(const std::string& vertex_source,
                                 const std::vector<float>& triangles, std::vector<float>* clip) {
  GlObjects gl;
  std::string error = BuildProgram(vertex_source, nullptr, &gl, "gl_Position");
  if (!error.empty()) return error;
  UploadTriangles(triangles, &gl);
  // Drawing needs a complete framebuffer even with the rasterizer off (the surfaceless context's
  // default one is not).
  if (error = BindFramebuffer(1, 1, GlDepth{}, &gl); !error.empty()) return error;
  const size_t count = triangles.size() / 3;
  GLuint feedback = 0;
  glGenBuffers(1, &feedback);
  glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, feedback);
  glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, static_cast<GLsizeiptr>(count * 4 * sizeof(float)),
               nullptr, GL_STATIC_READ);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, feedback);
  glUseProgram(gl.program);
  glEnable(GL_RASTERIZER_DISCARD);
  glBeginTransformFeedback(GL_POINTS);
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(count));
  glEndTransformFeedback();
  glDisable(GL_RASTERIZER_DISCARD);
  clip->assign(count * 4, 0.0f);
  glGetBufferSubData(GL_TRANSFORM_FEEDBACK_BUFFER, 0,
                     static_cast<GLsizeiptr>(count * 4 * sizeof(float)), clip->data());
  error = GlErrorText("transform feedback");
  glDeleteBuffers(1, &feedback);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glUseProgram(0);
  glBindVertexArray(0);
  return error;
}

// Over the covered pixels of a camera-image readback: the largest distance between the pixel's
// centre and the lens's pixel (PixelFromWorld) of the world point read there.
struct WarpErrors {
  int covered = 0;
  int not_in_scene = 0;
  double max_pixel_error = 0.0;
  double max_depth_error = 0.0;
  Eigen::Vector2d worst_pixel = Eigen::Vector2d::Constant(-1.0);
};

// `depth`: also compare the depth buffer with the pinhole window depth of the point (renders).
WarpErrors MeasureAgainstLens(const Camera& camera, const Readback& readback,
                              const GlDepth* depth) {
  const int width = camera.image_size.width;
  const int height = camera.image_size.height;
  const BackgroundFrame frame;
  const Eigen::Vector3d eye = CameraCenterInWorld(camera.cam_from_world);
  WarpErrors errors;
  for (int j = 0; j < height; ++j) {
    for (int i = 0; i < width; ++i) {
      const size_t index = static_cast<size_t>(j) * width + i;
      const float* rgba = &readback.rgba[4 * index];
      if (rgba[3] != 1.0f) continue;  // uncovered, or a bilinear tap off the scene
      ++errors.covered;
      const Eigen::Vector3d point_in_world(rgba[0], rgba[1], rgba[2]);
      int face_index = -1;
      if (Classify(point_in_world, eye, frame, &face_index) == kNoSurface) ++errors.not_in_scene;
      const Eigen::Vector2d pixel(i, height - 1 - j);
      const std::optional<Eigen::Vector2d> projection = PixelFromWorld(camera, point_in_world);
      const double error = projection ? (*projection - pixel).norm() : kInfinity;
      if (!(error <= errors.max_pixel_error)) {
        errors.max_pixel_error = error;
        errors.worst_pixel = pixel;
      }
      if (depth != nullptr) {
        const double z = (camera.cam_from_world * point_in_world).z();
        errors.max_depth_error =
            std::max(errors.max_depth_error,
                     std::abs(readback.depth[index] -
                              ExpectedWindowDepth(z, depth->reversed_z, Projection::kPerspective)));
      }
    }
  }
  return errors;
}

using LensShaderParam = std::tuple<LensCase, DepthCase>;

class LensShaderRenderTest : public GlTest, public testing::WithParamInterface<LensShaderParam> {};

// The per-vertex lens, as exported (--to glsl, the text verbatim): at every vertex the GL puts
// world points within kMaxPixelError (1e-3 px) of the lens's pixel, with the pinhole's depth;
// between vertices within the tessellation target the docs' rule promises.
TEST_P(LensShaderRenderTest,
       VerticesWithin1em3PxMeasured3em5_PixelsWithinTarget1em2PxMeasured6em3) {
  const auto& [lens, depth_case] = GetParam();
  const Camera camera = LensCamera(lens);
  const std::string vertex_shader = "#version 330 core\n" + LensGlslText(camera, depth_case.depth) +
                                    R"(layout(location = 0) in vec3 world_position;
out vec3 v_world_position;
void main() {
  v_world_position = world_position;
  gl_Position = camproj_projection * camproj_lens(camproj_view * vec4(world_position, 1.0));
}
)";
  // Tessellate as docs/exports.md says: every visible edge <= LensMaxEdgePx(target).
  const double max_edge_px = LensMaxEdgePx(camera, kTessellationTargetPx);
  const int box_cells =
      CellsForEdge(2, max_edge_px, camera, [](int cells) { return TessellatedScene(cells, 0); });
  const int background_cells = CellsForEdge(kBackgroundGrid, max_edge_px, camera,
                                            [](int cells) { return TessellatedScene(0, cells); });
  const std::vector<float> triangles = TessellatedScene(box_cells, background_cells);

  // 1. Vertices: gl_Position from the GL itself, against PixelFromWorld in double, for every
  // vertex in front of the near plane whose pixel is in the image.
  std::vector<float> clip;
  std::string error = CaptureClipPositions(vertex_shader, triangles, &clip);
  ASSERT_TRUE(error.empty()) << error;
  const int width = kImageSize.width;
  const int height = kImageSize.height;
  // Beyond LensRadiusLimit (the fold, or twice the image's radius) the model is not a lens any
  // more (past the fold it maps points back into the image); there the function must put every
  // vertex outside the image instead.
  const double r_limit = LensRadiusLimit(camera);
  const auto in_image = [&](const Eigen::Vector2d& pixel) {
    return pixel.x() >= -0.5 && pixel.x() <= width - 0.5 && pixel.y() >= -0.5 &&
           pixel.y() <= height - 0.5;
  };
  int vertices_in_image = 0;
  int beyond_limit = 0;
  int beyond_limit_in_image = 0;
  double max_vertex_error = 0.0;
  double max_vertex_depth_error = 0.0;
  for (size_t v = 0; v < triangles.size() / 3; ++v) {
    const Eigen::Vector3d point_in_world(triangles[3 * v], triangles[3 * v + 1],
                                         triangles[3 * v + 2]);
    const Eigen::Vector3d point_in_cam = camera.cam_from_world * point_in_world;
    if (point_in_cam.z() <= kZNear) continue;
    const Eigen::Vector4d c(clip[4 * v], clip[4 * v + 1], clip[4 * v + 2], clip[4 * v + 3]);
    const Eigen::Vector2d window((c.x() / c.w() + 1.0) * width / 2.0,
                                 (c.y() / c.w() + 1.0) * height / 2.0);
    const Eigen::Vector2d pixel(window.x() - 0.5, height - window.y() - 0.5);
    if (point_in_cam.head<2>().norm() / point_in_cam.z() >= r_limit) {
      ++beyond_limit;
      beyond_limit_in_image += in_image(pixel);
      continue;
    }
    const std::optional<Eigen::Vector2d> expected = PixelFromWorld(camera, point_in_world);
    if (!expected || !in_image(*expected)) continue;
    ++vertices_in_image;
    max_vertex_error = std::max(max_vertex_error, (pixel - *expected).norm());
    const double z_ndc = c.z() / c.w();
    const double window_depth =
        depth_case.depth.clip_depth == ClipDepth::kZeroToOne ? z_ndc : (z_ndc + 1.0) / 2.0;
    max_vertex_depth_error = std::max(
        max_vertex_depth_error,
        std::abs(window_depth - ExpectedWindowDepth(point_in_cam.z(), depth_case.depth.reversed_z,
                                                    Projection::kPerspective)));
  }

  // 2. Pixels: the rendered world point at every covered pixel.
  Readback readback;
  error = RenderWorldPositions(vertex_shader, triangles, width, height, Eigen::Matrix4d::Identity(),
                               Eigen::Matrix4d::Identity(), depth_case.depth, &readback);
  ASSERT_TRUE(error.empty()) << error;
  const WarpErrors pixels = MeasureAgainstLens(camera, readback, &depth_case.depth);
  const double covered_fraction = static_cast<double>(pixels.covered) / (width * height);

  std::printf(
      "[ lens     ] glsl %s/%s: %zu triangles (box %d, background %d cells a side, edges "
      "<= %.3g px); %d vertices in the image, max vertex error %.3g px, depth %.3g; %d "
      "beyond r_limit, %d of them drawn in the image; "
      "pixels: covered %.4f, max error %.3g px (target %.3g), depth %.3g\n",
      lens.name, depth_case.name, triangles.size() / 9, box_cells, background_cells, max_edge_px,
      vertices_in_image, max_vertex_error, max_vertex_depth_error, beyond_limit,
      beyond_limit_in_image, covered_fraction, pixels.max_pixel_error, kTessellationTargetPx,
      pixels.max_depth_error);
  RecordProperty("max_vertex_error_px", std::to_string(max_vertex_error));
  RecordProperty("max_pixel_error_px", std::to_string(pixels.max_pixel_error));

  EXPECT_GE(vertices_in_image, 1000);
  EXPECT_LE(max_vertex_error, kMaxPixelError);
  EXPECT_LE(max_vertex_depth_error, kMaxDepthError);
  EXPECT_EQ(beyond_limit_in_image, 0) << "vertices beyond r_limit folded back into the image";
  EXPECT_GE(covered_fraction, kMinCoveredFraction);
  EXPECT_EQ(pixels.not_in_scene, 0);
  EXPECT_LE(pixels.max_pixel_error, kTessellationTargetPx + kMaxPixelError)
      << "at image pixel " << pixels.worst_pixel.transpose();
  EXPECT_LE(pixels.max_depth_error, kMaxDepthError);
}

std::string LensShaderParamName(const testing::TestParamInfo<LensShaderParam>& info) {
  return std::string(std::get<0>(info.param).name) + "_" + std::get<1>(info.param).name;
}

INSTANTIATE_TEST_SUITE_P(
    LensesAndDepths, LensShaderRenderTest,
    testing::Combine(
        testing::ValuesIn(kLensCases),
        testing::Values(DepthCase{"NegativeOneToOne", {ClipDepth::kNegativeOneToOne, false}},
                        DepthCase{"ZeroToOneReversed", {ClipDepth::kZeroToOne, true}})),
    LensShaderParamName);

constexpr char kFullScreenVertexShader[] = R"(#version 330 core
void main() {  // one triangle covering the viewport
  vec2 corner = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(corner, 0.0, 1.0);
}
)";

// The STMap pass: the map is read at the output pixel, the source bilinearly where it says.
// u_source_valid_alpha: with the undistortion map, alpha < 1 marks no source.
constexpr char kStMapFragmentShader[] = R"(#version 330 core
uniform sampler2D u_map;
uniform sampler2D u_source;
layout(location = 0) out vec4 color;
void main() {
  vec4 st = texelFetch(u_map, ivec2(gl_FragCoord.xy), 0);
  color = st.a < 1.0 ? vec4(0.0) : texture(u_source, st.rg);
}
)";

constexpr char kMeshVertexShader[] = R"(#version 330 core
layout(location = 0) in vec2 distorted_uv;
layout(location = 1) in vec2 undistorted_uv;
noperspective out vec2 v_uv;
void main() {
  v_uv = undistorted_uv;
  gl_Position = vec4(distorted_uv * 2.0 - 1.0, 0.0, 1.0);
}
)";

constexpr char kMeshFragmentShader[] = R"(#version 330 core
uniform sampler2D u_source;
noperspective in vec2 v_uv;
layout(location = 0) out vec4 color;
void main() { color = texture(u_source, v_uv); }
)";

// A post-process pass into a width x height framebuffer: the full-screen STMap pass when `mesh`
// is null, else the mesh's triangles. Textures unit 0 = source, unit 1 = map.
std::string WarpPass(int width, int height, GLuint source, GLuint map, const nlohmann::json* mesh,
                     Readback* readback) {
  GlObjects gl;
  std::string error = mesh ? BuildProgram(kMeshVertexShader, kMeshFragmentShader, &gl)
                           : BuildProgram(kFullScreenVertexShader, kStMapFragmentShader, &gl);
  if (!error.empty()) return error;
  glGenVertexArrays(1, &gl.vertex_array);
  glBindVertexArray(gl.vertex_array);
  GLuint buffers[2] = {0, 0};
  std::vector<unsigned> indices;
  if (mesh != nullptr) {
    glGenBuffers(2, buffers);
    const std::vector<float> distorted = (*mesh)["distorted_uv"].get<std::vector<float>>();
    const std::vector<float> undistorted = (*mesh)["undistorted_uv"].get<std::vector<float>>();
    indices = (*mesh)["triangles"].get<std::vector<unsigned>>();
    glGenBuffers(1, &gl.vertex_buffer);
    std::vector<float> interleaved;
    for (size_t i = 0; i < distorted.size() / 2; ++i) {
      interleaved.insert(interleaved.end(), {distorted[2 * i], distorted[2 * i + 1],
                                             undistorted[2 * i], undistorted[2 * i + 1]});
    }
    glBindBuffer(GL_ARRAY_BUFFER, gl.vertex_buffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(interleaved.size() * sizeof(float)),
                 interleaved.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float),
                          reinterpret_cast<const void*>(2 * sizeof(float)));
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[0]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(indices.size() * sizeof(unsigned)), indices.data(),
                 GL_STATIC_DRAW);
  }
  error = BindFramebuffer(width, height, GlDepth{}, &gl);
  if (!error.empty()) {
    glDeleteBuffers(2, buffers);
    return error;
  }
  glDisable(GL_DEPTH_TEST);
  glUseProgram(gl.program);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, source);
  glUniform1i(glGetUniformLocation(gl.program, "u_source"), 0);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, map);
  glUniform1i(glGetUniformLocation(gl.program, "u_map"), 1);
  glActiveTexture(GL_TEXTURE0);
  if (mesh != nullptr) {
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(indices.size()), GL_UNSIGNED_INT, nullptr);
  } else {
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  error = GlErrorText("warping");
  glDeleteBuffers(2, buffers);
  if (!error.empty()) return error;
  return ReadFramebuffer(width, height, readback);
}

class LensWarpRenderTest : public GlTest, public testing::WithParamInterface<LensCase> {};

// The post-process lens: the pinhole camera rendered (by GL) into LensRenderTargetOf's buffer
// with its projection, then warped onto the image by the STMap (--to stmap) and by the
// distortion mesh (--to distortion-mesh, its default step). The smooth scene: the background
// plane alone (bilinear sampling across the box's silhouettes would mix surfaces).
TEST_P(LensWarpRenderTest, StMapWithin0p05PxMeasured3em4_MeshWithin0p05PxMeasured1em2) {
  const LensCase& lens = GetParam();
  const Camera camera = LensCamera(lens);
  const LensRenderTarget target = LensRenderTargetOf(camera);
  Readback pinhole;
  std::string error =
      RenderWorldPositions(kVertexShader, TessellatedScene(0, kBackgroundGrid), target.size.width,
                           target.size.height, LensRenderTargetClipFromGlEye(camera),
                           GlEyeFromWorld(camera.cam_from_world), GlDepth{}, &pinhole);
  ASSERT_TRUE(error.empty()) << error;
  int target_covered = 0;
  for (size_t i = 3; i < pinhole.rgba.size(); i += 4) target_covered += pinhole.rgba[i] == 1.0f;

  GlTextures textures;
  const GLuint source = textures.Upload(target.size.width, target.size.height, pinhole.rgba);
  const StMap map = LensStMap(camera, LensMapDirection::kDistort);
  ASSERT_EQ(map.width, kImageSize.width);
  ASSERT_EQ(map.height, kImageSize.height);
  const GLuint map_texture =
      textures.Upload(map.width, map.height, BottomRowFirst(map.width, map.height, map.rgba));

  Readback warped;
  error = WarpPass(map.width, map.height, source, map_texture, nullptr, &warped);
  ASSERT_TRUE(error.empty()) << error;
  const WarpErrors stmap = MeasureAgainstLens(camera, warped, nullptr);

  const nlohmann::json mesh = nlohmann::json::parse(LensDistortionMeshJson(camera, 0));
  error = WarpPass(map.width, map.height, source, map_texture, &mesh, &warped);
  ASSERT_TRUE(error.empty()) << error;
  const WarpErrors meshed = MeasureAgainstLens(camera, warped, nullptr);

  const double pixels = kImageSize.width * kImageSize.height;
  std::printf(
      "[ lens     ] warp %s: render target %d x %d (offset %d, %d), covered %.4f; stmap: "
      "covered %.4f, max error %.3g px; mesh (step %d px, its interpolation error %.3g "
      "px): covered %.4f, max error %.3g px\n",
      lens.name, target.size.width, target.size.height, target.offset_x, target.offset_y,
      target_covered / (1.0 * target.size.width * target.size.height), stmap.covered / pixels,
      stmap.max_pixel_error, mesh["step_px"].get<int>(),
      mesh["max_interpolation_error_px"].get<double>(), meshed.covered / pixels,
      meshed.max_pixel_error);
  RecordProperty("stmap_max_error_px", std::to_string(stmap.max_pixel_error));
  RecordProperty("mesh_max_error_px", std::to_string(meshed.max_pixel_error));
  EXPECT_EQ(target_covered, target.size.width * target.size.height)
      << "the background must fill the render target";
  for (const WarpErrors* errors : {&stmap, &meshed}) {
    EXPECT_EQ(errors->covered, kImageSize.width * kImageSize.height)
        << "every image pixel's bilinear taps lie in the render target";
    EXPECT_EQ(errors->not_in_scene, 0);
    EXPECT_LE(errors->max_pixel_error, kMaxWarpErrorPx)
        << "at image pixel " << errors->worst_pixel.transpose();
  }
  EXPECT_LE(mesh["max_interpolation_error_px"].get<double>(), kLensMeshErrorPx);
}

// The inverse: a plate (what the real camera shot; here the background plane ray-cast in double
// through CamRayFromPixel at every plate pixel) warped by the undistortion STMap
// (--to undistort-stmap) onto the render target's pinhole image, where CG rendered with the
// render target's projection overlays it: every pixel whose source lies inside the plate's
// pixel centres must hold the world point that pinhole projects onto that pixel.
TEST_P(LensWarpRenderTest, UndistortStMapWithin0p05PxMeasured0p033) {
  const LensCase& lens = GetParam();
  const Camera camera = LensCamera(lens);
  const LensRenderTarget target = LensRenderTargetOf(camera);
  const int width = kImageSize.width;
  const int height = kImageSize.height;
  const BackgroundFrame frame;
  const Eigen::Vector3d eye = CameraCenterInWorld(camera.cam_from_world);
  const Eigen::Matrix3d world_from_cam = camera.cam_from_world.rotation.transpose();
  std::vector<float> plate(static_cast<size_t>(width) * height * 4, 0.0f);  // row 0 = bottom
  for (int j = 0; j < height; ++j) {
    for (int i = 0; i < width; ++i) {
      const Eigen::Vector3d ray =
          world_from_cam * CamRayFromPixel(camera.intrinsics, {i, height - 1 - j});
      const double t = (kBackgroundOffset - frame.normal.dot(eye)) / frame.normal.dot(ray);
      ASSERT_GT(t, 0.0);
      const Eigen::Vector3d point = eye + t * ray;
      float* texel = &plate[(static_cast<size_t>(j) * width + i) * 4];
      texel[0] = static_cast<float>(point.x());
      texel[1] = static_cast<float>(point.y());
      texel[2] = static_cast<float>(point.z());
      texel[3] = 1.0f;
    }
  }
  GlTextures textures;
  const GLuint source = textures.Upload(width, height, plate);
  const StMap map = LensStMap(camera, LensMapDirection::kUndistort);
  ASSERT_EQ(map.width, target.size.width);
  ASSERT_EQ(map.height, target.size.height);
  const GLuint map_texture =
      textures.Upload(map.width, map.height, BottomRowFirst(map.width, map.height, map.rgba));
  Readback warped;
  const std::string error = WarpPass(map.width, map.height, source, map_texture, nullptr, &warped);
  ASSERT_TRUE(error.empty()) << error;

  int inside = 0;
  int off_plate = 0;
  double max_error = 0.0;
  Eigen::Vector2d worst(-1.0, -1.0);
  for (int y = 0; y < map.height; ++y) {  // map row y = target pixel row v = y
    for (int x = 0; x < map.width; ++x) {
      const float* st = &map.rgba[(static_cast<size_t>(y) * map.width + x) * 4];
      // The source in plate pixels (kCenter): window = st * size, pixel = window - 0.5 (y down).
      const double u = st[0] * width - 0.5;
      const double v = (1.0 - st[1]) * height - 0.5;
      const bool taps_inside =
          st[3] == 1.0f && u >= 0.0 && u <= width - 1.0 && v >= 0.0 && v <= height - 1.0;
      const size_t index = static_cast<size_t>(map.height - 1 - y) * map.width + x;
      const float* rgba = &warped.rgba[4 * index];
      if (!taps_inside) {
        off_plate += st[3] != 1.0f && rgba[3] != 0.0f;  // no source: the pass writes nothing
        continue;
      }
      ++inside;
      const Eigen::Vector3d point_in_cam =
          camera.cam_from_world * Eigen::Vector3d(rgba[0], rgba[1], rgba[2]);
      const double error =
          (PixelFromCam(target.intrinsics, point_in_cam) - Eigen::Vector2d(x, y)).norm();
      if (!(error <= max_error)) {
        max_error = error;
        worst = Eigen::Vector2d(x, y);
      }
    }
  }
  std::printf(
      "[ lens     ] undistort %s: render target %d x %d, %d pixels from inside the plate, "
      "max error %.3g px\n",
      lens.name, map.width, map.height, inside, max_error);
  RecordProperty("undistort_max_error_px", std::to_string(max_error));
  // The plate's footprint on the render target is about the plate's area (the lens scales area
  // by ~0.6 to ~1.6 over these images).
  EXPECT_GE(inside, width * height / 2);
  EXPECT_EQ(off_plate, 0) << "pixels without a source must stay empty (alpha 0)";
  EXPECT_LE(max_error, kMaxWarpErrorPx) << "at render target pixel " << worst.transpose();
}

std::string LensParamName(const testing::TestParamInfo<LensCase>& info) { return info.param.name; }

INSTANTIATE_TEST_SUITE_P(Lenses, LensWarpRenderTest, testing::ValuesIn(kLensCases), LensParamName);

// Survey-scale coordinates in float32 (docs/conventions.md, section 12): the Centered case scaled
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
