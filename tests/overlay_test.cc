// The overlay picture, decoded and checked where its markers must be (camproj/overlay.h).
#include "camproj/overlay.h"

#include <unistd.h>

#include <filesystem>
#include <limits>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camproj/camera_file.h"
#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/points_file.h"
#include "camproj/pose.h"

namespace camproj {
namespace {

namespace fs = std::filesystem;

struct Scene {
  Camera camera;
  Correspondences points;
};

Scene Projector() {
  return {ReadCameraFile(std::string(CAMPROJ_DATA_DIR) + "/projector/truth.json"),
          ReadCorrespondencesFile(std::string(CAMPROJ_DATA_DIR) + "/projector/points.csv")};
}

fs::path Output(const std::string& name) {
  const fs::path folder = fs::temp_directory_path() / ("camproj_overlay_test_" + std::to_string(getpid()));
  fs::create_directories(folder);
  return folder / name;
}

// The largest channel difference between `pixel` and the closest of the pixels within `reach`
// of `at` (antialiased markers are a couple of pixels wide).
int ClosestColourDistance(const cv::Mat& image, const Eigen::Vector2d& at, const cv::Vec3b& pixel,
                          int reach) {
  int best = 1 << 30;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const int x = static_cast<int>(std::lround(at.x())) + dx;
      const int y = static_cast<int>(std::lround(at.y())) + dy;
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      const cv::Vec3b c = image.at<cv::Vec3b>(y, x);
      int d = 0;
      for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(c[k] - pixel[k]));
      best = std::min(best, d);
    }
  }
  return best;
}

TEST(OverlayTest, MarkersWhereThePointsProjectIdsThatDoNotOverlapOutliersInVermillion) {
  const Scene scene = Projector();
  OverlayOptions options;
  options.outliers = {2};  // the third point drawn as an outlier
  const fs::path path = Output("overlay.png");
  const OverlayStats stats = WriteOverlayImage(scene.camera, scene.points, options, path.string());
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  const int w = scene.camera.image_size.width, h = scene.camera.image_size.height;
  EXPECT_EQ(image.cols, w);
  EXPECT_EQ(image.rows, h);
  EXPECT_EQ(stats.outliers, 1);
  EXPECT_EQ(stats.drawn, 19);
  // The magnification: the largest kept residual drawn residual_fraction of the image's smaller
  // side or less, but more than 2/5 of it (1, 2, 5 steps round down by at most 5/2).
  const double drawn_px = stats.magnify * stats.largest_residual_px;
  EXPECT_LE(drawn_px, options.residual_fraction * h + 1e-9);
  EXPECT_GT(drawn_px, 0.4 * options.residual_fraction * h);

  ASSERT_EQ(stats.labels.size(), scene.points.pixels.size());
  for (size_t i = 0; i < scene.points.pixels.size(); ++i) {
    const OverlayLabel& label = stats.labels[i];
    EXPECT_EQ(label.id, scene.points.ids[i]);
    const std::optional<Eigen::Vector2d> predicted =
        PixelFromWorld(scene.camera, scene.points.points_in_world[i]);
    ASSERT_TRUE(predicted);
    if (i == 2) {
      EXPECT_EQ(label.kind, "outlier");
      // A crossed vermillion ring at the observed pixel (BGR 31, 90, 255).
      EXPECT_LE(ClosestColourDistance(image, scene.points.pixels[i], cv::Vec3b(31, 90, 255), 1), 40);
    } else {
      EXPECT_EQ(label.kind, "point");
      // The reprojection's cross is white at its centre (at most a pixel of antialiasing off).
      EXPECT_LE(ClosestColourDistance(image, *predicted, cv::Vec3b(255, 255, 255), 1), 40)
          << "id " << label.id;
    }
    // Ids inside the image, and apart: no two boxes overlap.
    EXPECT_GE(label.box[0], 0.0);
    EXPECT_GE(label.box[1], 0.0);
    EXPECT_LE(label.box[0] + label.box[2], w);
    EXPECT_LE(label.box[1] + label.box[3], h);
    for (size_t j = 0; j < i; ++j) {
      const Eigen::Vector4d& a = label.box;
      const Eigen::Vector4d& b = stats.labels[j].box;
      const bool apart = a[0] + a[2] <= b[0] || b[0] + b[2] <= a[0] || a[1] + a[3] <= b[1] ||
                         b[1] + b[3] <= a[1];
      EXPECT_TRUE(apart) << "ids " << label.id << " and " << stats.labels[j].id << " overlap";
    }
  }
  // Text pixels where the labels are: each box holds light (id) pixels (the ground is 40, the
  // halo black; white text is 255, vermillion 133 in grey).
  for (const OverlayLabel& label : stats.labels) {
    const cv::Rect box(static_cast<int>(label.box[0]), static_cast<int>(label.box[1]),
                       static_cast<int>(label.box[2]), static_cast<int>(label.box[3]));
    cv::Mat grey;
    cv::cvtColor(image(box & cv::Rect(0, 0, w, h)), grey, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(grey > 100), 10) << "no text in the box of id " << label.id;
  }
  fs::remove_all(path.parent_path());
}

TEST(OverlayTest, ObservedPixelsOutsideTheImageBecomeArrowsAtTheBorder) {
  Scene scene = Projector();
  scene.points.pixels[0] = Eigen::Vector2d(-300.0, 500.0);
  const fs::path path = Output("outside.jpg");
  const OverlayStats stats = WriteOverlayImage(scene.camera, scene.points, {}, path.string());
  EXPECT_EQ(stats.outside, 1);
  EXPECT_EQ(stats.labels[0].kind, "outside");
  EXPECT_GE(stats.labels[0].box[0], 0.0);  // its id is inside the image
  // The far-off point does not set the scale: the others' residuals (~1 px) do.
  EXPECT_LT(stats.largest_residual_px, 10.0);
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  EXPECT_FALSE(image.empty());
  fs::remove_all(path.parent_path());
}

// A point outside the image keeps what else it is in its label (an outlier, behind the camera:
// "outside" overwrote both), and its position, like the labels file's, is in the user's pixel
// convention (the corner convention's were written in the centre's).
TEST(OverlayTest, LabelsOfPointsOutsideTheImageSayWhatTheyAreInTheUsersConvention) {
  Scene scene = Projector();
  // kCenter pixels a quarter pixel off the whole ones: the corner convention's are a half on.
  scene.points.pixels[0] = Eigen::Vector2d(-300.25, 500.25);
  scene.points.pixels[1] = Eigen::Vector2d(2500.0, 400.0);
  scene.points.points_in_world[2] = 3.0 * CameraCenterInWorld(scene.camera.cam_from_world);
  scene.points.pixels[2] = Eigen::Vector2d(100.25, -200.25);
  OverlayOptions options;
  options.outliers = {1};
  options.pixel_origin = PixelOrigin::kCorner;
  const OverlayStats stats =
      DrawOverlayImage(scene.camera, scene.points, options, ImageFormat::kPng).stats;
  EXPECT_EQ(stats.outside, 3);
  const std::vector<OverlayLabel>& labels = stats.labels;
  EXPECT_EQ(labels[0].text, labels[0].id + " (at -300, 501)");  // -299.75, 500.75
  EXPECT_EQ(labels[1].text.rfind(labels[1].id + " (at 2500, 400; ", 0), 0u) << labels[1].text;
  EXPECT_EQ(labels[1].kind, "outside");
  EXPECT_NE(labels[1].text.find(" px off)"), std::string::npos) << labels[1].text;
  EXPECT_EQ(labels[2].text, labels[2].id + " (at 101, -200; behind)");  // 100.75, -199.75
  // The labels file: u, v and left, top half a pixel on from the (kCenter) labels, to its 10
  // significant digits (5e-7 px at 1e3 px).
  constexpr double kCsvPx = 1e-6;
  std::istringstream csv(OverlayLabelsCsv(stats, PixelOrigin::kCorner));
  std::string line;
  std::getline(csv, line);
  for (size_t i = 0; std::getline(csv, line); ++i) {
    std::vector<double> values;
    std::istringstream fields(line.substr(line.find(',', line.find(',') + 1) + 1));
    for (std::string field; std::getline(fields, field, ',');) values.push_back(std::stod(field));
    ASSERT_EQ(values.size(), 7u) << line;
    EXPECT_NEAR(values[0], labels[i].anchor.x() + 0.5, kCsvPx) << line;
    EXPECT_NEAR(values[1], labels[i].anchor.y() + 0.5, kCsvPx) << line;
    EXPECT_NEAR(values[2], labels[i].box[0] + 0.5, kCsvPx) << line;
    EXPECT_NEAR(values[3], labels[i].box[1] + 0.5, kCsvPx) << line;
  }
}

// A 1000 x 800 camera looking down +z, f 1000 px, its principal point at the image's centre; near,
// far as each test needs.
Camera ThousandPixelCamera() {
  Camera camera;
  camera.image_size = {1000, 800};
  camera.intrinsics.fx = camera.intrinsics.fy = 1000.0;
  camera.intrinsics.cx = 499.5;
  camera.intrinsics.cy = 399.5;
  return camera;
}

cv::Mat Decoded(const OverlayPicture& picture) {
  return cv::imdecode(std::vector<uchar>(picture.encoded.begin(), picture.encoded.end()),
                      cv::IMREAD_COLOR);
}

// A reprojection 2^28 px away: its residual line runs to the image's edge along the true
// direction, and nothing is drawn where the wrapped fixed-point coordinate would land (before
// session 37 the cross was drawn at the image centre).
TEST(OverlayTest, FarReprojectionIsClippedNotWrapped) {
  Camera camera = ThousandPixelCamera();
  camera.z_near = 0.5;
  camera.z_far = 10.0;
  Correspondences points;
  points.points_in_world = {{268435.4565, 0.0, 1.0}, {0.1, 0.1, 2.0}};
  points.pixels = {{300.0, 399.5}, {550.0, 450.0}};
  points.ids = {"far", "a"};
  OverlayOptions options;
  options.magnify = 1.0;
  const OverlayPicture picture = DrawOverlayImage(camera, points, options, ImageFormat::kPng);
  const cv::Mat image = Decoded(picture);
  ASSERT_FALSE(image.empty());
  const cv::Vec3b background = image.at<cv::Vec3b>(700, 100);
  // The wrapped place: u = 268435956 px, x 16 = 4294975296 = 2^32 + 8000 -> 500 px. The
  // residual line runs through it; the cross's vertical arm would stand above and below it.
  for (const double dv : {-6.0, -4.0, 4.0, 6.0}) {
    EXPECT_EQ(ClosestColourDistance(image, {500.0, 399.5 + dv}, background, 0), 0) << "dv " << dv;
  }
  // The line from the observed pixel to the right edge, on the row of both.
  for (const double u : {400.0, 700.0, 995.0}) {
    EXPECT_GT(ClosestColourDistance(image, {u, 399.5}, background, 0), 30) << "u " << u;
  }
  EXPECT_NEAR(picture.stats.labels[0].residual_px, 268435956.0 - 300.0, 1.0);
}

// A point in front of the camera whose pixel is beyond a double (x / z = 1e308 / 1e-10) has no
// reprojection like a point behind, but is counted and labelled as what it is (it was counted
// "behind the camera" before).
TEST(OverlayTest, APointInFrontWithAPixelBeyondADoubleIsNotCalledBehind) {
  Camera camera = ThousandPixelCamera();
  camera.z_near = 1e-12;
  camera.z_far = 10.0;
  Correspondences points;
  points.points_in_world = {{1e308, 0.0, 1e-10}, {0.0, 0.0, -1.0}, {0.1, 0.1, 2.0}};
  points.pixels = {{300.0, 399.5}, {400.0, 399.5}, {550.0, 450.0}};
  points.ids = {"beyond", "behind", "a"};
  const OverlayPicture picture = DrawOverlayImage(camera, points, {}, ImageFormat::kPng);
  EXPECT_EQ(picture.stats.no_pixel, 1);
  EXPECT_EQ(picture.stats.behind, 1);
  EXPECT_EQ(picture.stats.drawn, 1);
  EXPECT_EQ(picture.stats.labels[0].kind, "no-pixel");
  EXPECT_EQ(picture.stats.labels[0].residual_px, -1.0);
  EXPECT_EQ(picture.stats.labels[1].kind, "behind");
}

// A residual beyond a double's range (a reprojection at 1.7e308 px) is the colour scale's top, as
// an infinite one is: inf / inf reached the lookup as NaN, whose lround picked the bottom (the
// colour of a perfect point) on x86.
TEST(OverlayTest, AnOverflowingResidualIsTheTopOfTheColourScale) {
  Camera camera = ThousandPixelCamera();
  camera.z_near = 0.5;
  camera.z_far = 10.0;
  Correspondences points;
  points.points_in_world = {{0.0, 0.0, 2.0}, {1.7e305, 0.0, 1.0}};
  points.pixels = {{499.5, 399.5}, {300.0, 399.5}};
  points.ids = {"a", "far"};
  OverlayOptions options;
  options.magnify = 1.0;
  const OverlayPicture picture = DrawOverlayImage(camera, points, options, ImageFormat::kPng);
  EXPECT_EQ(picture.stats.largest_residual_px, std::numeric_limits<double>::infinity());
  const cv::Mat image = Decoded(picture);
  ASSERT_FALSE(image.empty());
  // The far point's observed ring (radius 6 x 1.48 px at 800 rows, at (300, 399.5)) is in
  // viridis's top, yellow (BGR 37, 231, 253); nothing else drawn within 10 px of it is yellow
  // (before session 43 the ring was viridis's bottom, purple, and this found no yellow).
  const Eigen::Vector2d observed(300.0, 399.5);
  EXPECT_LE(ClosestColourDistance(image, observed, cv::Vec3b(37, 231, 253), 10), 40);
}

// A JPEG background cut short is refused (libjpeg decoded it with a warning and garbage below
// the cut, exit 0, before session 37); baseline, progressive and restart-interval JPEGs, and one
// with data after its end (a phone's motion photo), are drawn on.
TEST(OverlayTest, TruncatedJpegBackgroundIsRefused) {
  Scene scene = Projector();
  const int w = scene.camera.image_size.width;
  const int h = scene.camera.image_size.height;
  cv::Mat photo(h, w, CV_8UC3);
  cv::randu(photo, cv::Scalar::all(0), cv::Scalar::all(255));
  const std::vector<std::vector<int>> encodings = {
      {}, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}, {cv::IMWRITE_JPEG_RST_INTERVAL, 1}};
  for (const std::vector<int>& parameters : encodings) {
    std::vector<uchar> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", photo, jpeg, parameters));
    const std::string whole(jpeg.begin(), jpeg.end());
    auto draw_on = [&](const std::string& bytes) {
      const std::string path = Output("background.jpg").string();
      WriteFileAtomically(path, bytes);
      OverlayOptions options;
      options.background_path = path;
      return DrawOverlayImage(scene.camera, scene.points, options, ImageFormat::kPng);
    };
    EXPECT_NO_THROW(draw_on(whole));
    EXPECT_NO_THROW(draw_on(whole + std::string(5000, 'x')));  // data after the end
    for (const double kept : {0.3, 0.9, 0.999}) {
      const std::string cut = whole.substr(0, static_cast<size_t>(kept * whole.size()));
      try {
        draw_on(cut);
        ADD_FAILURE() << "a JPEG cut at " << kept << " of its bytes was drawn on";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("the file is truncated"), std::string::npos) << e.what();
      }
    }
  }
}

// A PNG background cut short is refused by its own chunk walk, before libpng prints anything.
TEST(OverlayTest, TruncatedPngBackgroundIsRefused) {
  Scene scene = Projector();
  cv::Mat photo(scene.camera.image_size.height, scene.camera.image_size.width, CV_8UC3,
                cv::Scalar(40, 80, 120));
  std::vector<uchar> png;
  ASSERT_TRUE(cv::imencode(".png", photo, png));
  const std::string whole(png.begin(), png.end());
  const std::string path = Output("background.png").string();
  OverlayOptions options;
  options.background_path = path;
  WriteFileAtomically(path, whole);
  EXPECT_NO_THROW(DrawOverlayImage(scene.camera, scene.points, options, ImageFormat::kPng));
  for (const size_t cut : {size_t{40}, whole.size() / 2, whole.size() - 1}) {
    WriteFileAtomically(path, whole.substr(0, cut));
    try {
      DrawOverlayImage(scene.camera, scene.points, options, ImageFormat::kPng);
      ADD_FAILURE() << "a PNG cut at " << cut << " bytes was drawn on";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the PNG ends before its IEND chunk"), std::string::npos)
          << e.what();
    }
  }
}

TEST(OverlayTest, OutlierIndexBeyondThePointsIsRefused) {
  const Scene scene = Projector();
  OverlayOptions options;
  options.outliers = {20};
  EXPECT_THROW(WriteOverlayImage(scene.camera, scene.points, options, Output("x.png").string()),
               std::invalid_argument);
}

}  // namespace
}  // namespace camproj
