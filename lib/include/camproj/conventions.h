// camproj conventions, in brief. docs/conventions.md is the one full statement; every other header
// refers to it rather than restating it.
//
// Frames (transforms are named target_from_source: p_in_cam = cam_from_world * p_in_world):
//   world    the user's frame, any units, must be right-handed.
//   cam      computer-vision camera (OpenCV): x right, y down, z forward (depth z > 0 in front).
//   gl_eye   OpenGL eye space: x right, y up, looking down -z. gl_eye_from_cam = diag(1, -1, -1).
//   clip     gl_eye after the projection matrix (clip_from_gl_eye); ndc = clip.xyz / clip.w.
//   window   GL window coordinates: origin at the bottom-left *corner* of the viewport, y up.
//   pixel    image coordinates, y down. Default origin kCenter (OpenCV): (0,0) is the centre of the
//            top-left pixel. kCorner (COLMAP, nerfstudio): that centre is at (0.5, 0.5).
//            For kCenter: x_win = u + 0.5, y_win = H - (v + 0.5).
// Clip depth: kNegativeOneToOne (OpenGL's default, "NO") or kZeroToOne ("ZO": Vulkan, D3D,
//   glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)); optionally reversed-Z and an infinite far plane.
// Matrices are Eigen's default column-major: Matrix4d::data() uploads with transpose = GL_FALSE.
// Quaternions: Eigen's storage order (x, y, z, w).
#ifndef CAMPROJ_CONVENTIONS_H_
#define CAMPROJ_CONVENTIONS_H_

#include <string>

#include <Eigen/Core>

namespace camproj {

// Where pixel (0,0) sits; see the file comment.
enum class PixelOrigin { kCenter, kCorner };

// The clip-space depth range after the perspective divide.
enum class ClipDepth { kNegativeOneToOne, kZeroToOne };

// The largest image side, in pixels, a camera may have: camera files record sides up to it, and
// every pixel coordinate of such an image is exact in float32 to 1/16 px.
inline constexpr int kMaxImageSide = 1000000;

// Image size in pixels. Check() throws std::invalid_argument unless both are positive and at
// most kMaxImageSide.
struct ImageSize {
  int width = 0;
  int height = 0;
  void Check() const;
};

// Whether kCenter pixel `pixel` lies in an image of `size`: pixel centres at integers, so the
// image spans -0.5 to width - 0.5 and -0.5 to height - 0.5, its edges included (the one place
// this test is written: overlay, view, report, lens maps and the determination check use it).
inline bool PixelInImage(const Eigen::Vector2d& pixel, const ImageSize& size) {
  return pixel.x() >= -0.5 && pixel.x() <= size.width - 0.5 && pixel.y() >= -0.5 &&
         pixel.y() <= size.height - 0.5;
}

// The fixed change of axes between the computer-vision camera and OpenGL eye space.
Eigen::Matrix3d GlEyeFromCam();

// What to add to a pixel coordinate (u or v, or cx, cy) given in `from` to express it in `to`:
// +0.5 from kCenter to kCorner, -0.5 back, 0 otherwise. The only place the half pixel lives.
double PixelOriginShift(PixelOrigin from, PixelOrigin to);

// `pixel` re-expressed from one pixel origin to the other (adds PixelOriginShift to u and v).
Eigen::Vector2d ConvertPixelOrigin(const Eigen::Vector2d& pixel, PixelOrigin from, PixelOrigin to);

// GL window coordinates (origin at the bottom-left corner, y up) of an image pixel given in
// `origin`, for a viewport covering the whole image, and back. Throws on an invalid size.
Eigen::Vector2d WindowFromPixel(const Eigen::Vector2d& pixel, const ImageSize& size,
                                PixelOrigin origin = PixelOrigin::kCenter);
Eigen::Vector2d PixelFromWindow(const Eigen::Vector2d& window, const ImageSize& size,
                                PixelOrigin origin = PixelOrigin::kCenter);

const char* ToString(PixelOrigin origin);   // "center" | "corner"
const char* ToString(ClipDepth depth);      // "no" | "zo"
// Parse the strings above; throws std::invalid_argument naming the text otherwise.
PixelOrigin PixelOriginFromString(const std::string& text);
ClipDepth ClipDepthFromString(const std::string& text);

}  // namespace camproj

#endif  // CAMPROJ_CONVENTIONS_H_
