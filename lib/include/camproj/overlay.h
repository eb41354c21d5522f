// A picture of a fit that answers "which click is wrong?": each point's observed pixel (a ring
// coloured by its residual on a colour-blind-safe scale, viridis), its reprojection (a cross), the
// residual vector magnified by a factor stated in the legend, the point's id beside it (placed
// so that ids do not cover each other or the markers), the fit's outliers as crossed vermillion
// rings with no residual line, points outside the image as arrows at its border. Drawn on the
// camera's image, or on a blank canvas of its size (the picture has the image's size; the legend
// sits in the corner with the fewest points, under the markers). Pixels in kCenter
// (docs/conventions.md).
#ifndef CAMPROJ_OVERLAY_H_
#define CAMPROJ_OVERLAY_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/image_header.h"
#include "camproj/points_file.h"

namespace camproj {

struct OverlayOptions {
  // Residual vectors are drawn this many times their length, > 0; 0 (the default): chosen so
  // that the largest residual of a point the fit kept is drawn `residual_fraction` of the
  // image's smaller side long, rounded down to 1, 2 or 5 times a power of ten, at least 1.
  double magnify = 0.0;
  double residual_fraction = 0.08;  // in (0, 1]
  std::string background_path;  // image to draw on, PNG or JPEG; empty: blank
  // 0-based indices of the points the fit left out (the camera file's fit.outliers;
  // OutlierIndicesFromJsonText): crossed rings, no residual line, not in the colour scale.
  std::vector<int> outliers;
  // The convention of the user's pixels, in which a label writes one (the "(at u, v)" of a point
  // outside the image); the correspondences' pixels are kCenter whatever it is.
  PixelOrigin pixel_origin = PixelOrigin::kCenter;
  void Check() const;
};

// Where an id was written, for a reader of the picture (`camproj overlay --labels`) and tests.
struct OverlayLabel {
  std::string id;
  // "point" | "outlier" | "outside" (arrow at the border) | "behind" | "no-pixel" (in front, but
  // its pixel is beyond a double: PixelFromWorld gives none)
  std::string kind;
  Eigen::Vector2d anchor;    // the marker the label belongs to, kCenter px
  Eigen::Vector4d box;       // the text's box: left, top, width, height in image px
  double residual_px = -1;   // |reprojected - observed|; -1 behind the camera or no pixel
  std::string text;          // as drawn: "c4 (12 px off)", "c9 (at -300, 500; behind)"
};

struct OverlayStats {
  int drawn = 0;     // points the fit kept that are in front of the camera (outside ones included)
  int behind = 0;    // points behind the camera (ring and id, no reprojection)
  int no_pixel = 0;  // points in front whose pixel is beyond a double (ring and id, likewise)
  int outliers = 0;  // points drawn as outliers
  int outside = 0;   // observed pixels outside the image (arrows at the border)
  double magnify = 0.0;             // the magnification used
  double largest_residual_px = 0.0; // among the points the fit kept (the colour scale's top)
  std::vector<OverlayLabel> labels;  // one per point, in the order of the correspondences
};

// The picture, encoded, and what was drawn.
struct OverlayPicture {
  std::string encoded;  // the PNG or JPEG file's bytes
  OverlayStats stats;
};

// Draws the picture and encodes it as `format`, writing nothing (WriteOverlayImage writes it).
// Throws as WriteOverlayImage does, but for the output.
OverlayPicture DrawOverlayImage(const Camera& camera, const Correspondences& correspondences,
                                const OverlayOptions& options, ImageFormat format);

// Draws and writes the picture to `output_path` atomically, as PNG or JPEG by its extension
// (ImageFormatOfPath). Pixels of `correspondences` are in kCenter.
// Throws std::invalid_argument if the extension is neither, an outlier index is out of range, or
// the camera's image size is beyond kMaxImagePixels (before allocating anything); InputError if
// the background is not a PNG or JPEG, its header states another size as displayed (a JPEG's
// EXIF orientation applied: the background is drawn on as displayed) than the camera's (checked
// before decoding), it cannot be decoded, or the output cannot be written.
OverlayStats WriteOverlayImage(const Camera& camera, const Correspondences& correspondences,
                               const OverlayOptions& options, const std::string& output_path);

// The labels as CSV: id,kind,u,v,left,top,width,height,residual_px; u, v (the anchor) and left,
// top in `pixel_origin`'s convention.
std::string OverlayLabelsCsv(const OverlayStats& stats,
                             PixelOrigin pixel_origin = PixelOrigin::kCenter);

}  // namespace camproj

#endif  // CAMPROJ_OVERLAY_H_
