// A page to look at a camera and its points: `camproj view CAMERA.json [POINTS.csv] -o view.html`.
// One self-contained HTML file (three.js inlined, nothing fetched: it opens from disk) with
//  - an orbit view of the world points, the camera's frustum (near plane, a far plane, the image
//    plane with the photo on it), rays from the eye through each observed pixel, residuals
//    coloured by size (a colour-blind-safe scale), the fit's outliers marked, and an OBJ model;
//  - a view through the camera, rendered by three.js with the camera `camproj export --to three`
//    writes (docs/exports.md), loaded as that page says: the model points land on the observed
//    pixels there, so the page is a test of the export (tests/view_browser_test.cc);
//  - the fit report beside them (the camera file's `fit` record: model, left-out parameters and
//    why, sigmas, the worst points by id).
// Pixels are in kCenter (docs/conventions.md); the page converts to three's and the canvas's
// corner convention (+0.5 px) in one place (web/view.js, CornerFromCenter).
// Opened with the fragment #camproj-test, the page switches to the view through the camera,
// renders each point alone as a Gaussian spot, reads the pixels back and writes their centroids
// (kCenter) as JSON into <pre id="camproj-test-result">.
#ifndef CAMPROJ_VIEW_H_
#define CAMPROJ_VIEW_H_

#include <string>

#include "camproj/camera.h"
#include "camproj/points_file.h"

namespace camproj {

struct ViewOptions {
  // Photo shown on the image plane and behind the view through the camera: PNG or JPEG of the
  // camera's image size as displayed (a JPEG's EXIF orientation applied, as camproj overlay and
  // browsers apply it; such a JPEG is embedded turned upright, re-encoded). Empty: none.
  std::string image_path;
  // Wavefront OBJ in world units (`v` and `f` lines; others ignored; a file without a face is
  // refused), drawn in the orbit view. Empty: none.
  std::string mesh_path;
  std::string title;  // page title; empty: "camproj view: " + the camera's name
  void Check() const;  // nothing to check today; kept for the options-in convention
};

struct ViewStats {
  int points = 0;          // points drawn
  int behind = 0;          // points not in front of the camera (drawn, without a residual)
  int no_pixel = 0;        // points in front whose pixel is beyond a double (likewise)
  int outliers = 0;        // points the fit left out (the camera file's fit.outliers)
  int outside_image = 0;   // points whose projection falls outside the image
  int mesh_triangles = 0;
  size_t page_bytes = 0;
};

// The page's HTML. `camera_file_text` is the camera file's text, read for its `fit` record (the
// report; absent: no report); `camera_name` names the camera on the page. `correspondences`
// (pixels in kCenter) may be null: the camera alone. Throws InputError naming the file and line
// for a bad OBJ (a field that is not a number, a face index out of range, a face of fewer than 3
// vertices, more than 5e6 vertices or triangles) or a bad photo (not PNG/JPEG, another size as
// displayed than the camera's, cut short: RequireWholeImage); std::invalid_argument for an invalid camera.
std::string ViewPageHtml(const Camera& camera, const std::string& camera_file_text,
                         const std::string& camera_name, const Correspondences* correspondences,
                         const ViewOptions& options, ViewStats* stats = nullptr);

// ViewPageHtml written to `output_path` atomically (WriteFileAtomically).
ViewStats WriteViewPage(const Camera& camera, const std::string& camera_file_text,
                        const std::string& camera_name, const Correspondences* correspondences,
                        const ViewOptions& options, const std::string& output_path);

}  // namespace camproj

#endif  // CAMPROJ_VIEW_H_
