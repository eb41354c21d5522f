// bench --calibrate: Calibrate (calibrate.h) against cv::calibrateCamera on the same synthetic
// board sets — 5, 13 and 50 views of the 9 x 6 board (SynthesizeCalibrationViews, 640 x 480,
// fx 820, fy 826, k1 -0.21, k2 0.07, sigma 0.5 px), the same model (fx, fy, cx, cy, k1, k2;
// OpenCV with CALIB_ZERO_TANGENT_DIST | CALIB_FIX_K3 and its default termination): median wall
// time per calibration, the RMS, the focal length's error, and how far the two optima are apart.
#ifndef CAMPROJ_APPS_BENCH_CALIBRATE_BENCH_H_
#define CAMPROJ_APPS_BENCH_CALIBRATE_BENCH_H_

namespace camproj {
namespace bench {

// `bench --calibrate [--views N,N,...] [--sets K] [--out DIR]`; argv as main's. Returns the exit
// status: 0 ok, 1 usage.
int CalibrateMain(int argc, char** argv);

}  // namespace bench
}  // namespace camproj

#endif  // CAMPROJ_APPS_BENCH_CALIBRATE_BENCH_H_
