// libFuzzer target for the camera-file reader (camproj/camera_file.h).
//
// The contract under test: CameraFromJsonText (and CalibrationViewFromJsonText, for a view named
// "a") either returns a camera that passes Camera::Check or throws camproj::InputError. Anything
// else -- another exception type (it escapes and aborts), a crash, a leak, undefined behaviour, a
// hang -- is a finding. Besides, an
// accepted camera written back with CameraToJsonText must read back bit for bit (the writer
// promises full precision). A violated check prints what differs and aborts, so libFuzzer saves
// the input.
//
// Build and run: scripts/fuzz.sh.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "camproj/camera.h"
#include "camproj/camera_file.h"
#include "camproj/errors.h"

namespace {

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "camera_json_fuzzer: contract violated: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

void Expect(bool condition, const std::string& what) {
  if (!condition) Fail(what);
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <typename Matrix>
bool SameBits(const Matrix& a, const Matrix& b) {
  for (int i = 0; i < a.size(); ++i) {
    if (!SameBits(a.data()[i], b.data()[i])) return false;
  }
  return true;
}

bool Same(const camproj::Camera& a, const camproj::Camera& b) {
  const camproj::Intrinsics& ka = a.intrinsics;
  const camproj::Intrinsics& kb = b.intrinsics;
  return a.image_size.width == b.image_size.width && a.image_size.height == b.image_size.height &&
         SameBits(ka.fx, kb.fx) && SameBits(ka.fy, kb.fy) && SameBits(ka.cx, kb.cx) &&
         SameBits(ka.cy, kb.cy) && SameBits(ka.skew, kb.skew) && SameBits(ka.k1, kb.k1) &&
         SameBits(ka.k2, kb.k2) &&
         SameBits(a.cam_from_world.rotation, b.cam_from_world.rotation) &&
         SameBits(a.cam_from_world.translation, b.cam_from_world.translation) &&
         SameBits(a.z_near, b.z_near) && SameBits(a.z_far, b.z_far) &&
         a.world_origin.has_value() == b.world_origin.has_value() &&
         (!a.world_origin || SameBits(*a.world_origin, *b.world_origin));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // A calibration file's view (the dictionary's "views", "name", "camera"): the same contract.
  try {
    const camproj::Camera view = camproj::CalibrationViewFromJsonText(text, "fuzz.json", "a");
    view.Check();
  } catch (const camproj::InputError& e) {
    Expect(std::strlen(e.what()) > 0, "InputError with an empty message");
  } catch (const std::invalid_argument& e) {
    Fail(std::string("the reader returned a view's camera that fails Check: ") + e.what());
  }
  camproj::Camera camera;
  try {
    camera = camproj::CameraFromJsonText(text, "fuzz.json");
  } catch (const camproj::InputError& e) {
    Expect(std::strlen(e.what()) > 0, "InputError with an empty message");
    return 0;
  }
  try {
    camera.Check();
  } catch (const std::invalid_argument& e) {
    Fail(std::string("the reader returned a camera that fails Check: ") + e.what());
  }

  // Round trip. The writer derives views (frustum, GL matrices) that an extreme but valid camera
  // can push out of a double's range; it then throws std::invalid_argument, which is allowed.
  std::string written;
  try {
    written = camproj::CameraToJsonText(camera);
  } catch (const std::invalid_argument&) {
    return 0;
  }
  camproj::Camera again;
  try {
    again = camproj::CameraFromJsonText(written, "written.json");
  } catch (const camproj::InputError& e) {
    Fail(std::string("the written camera does not read back: ") + e.what() + "\n" + written);
  }
  Expect(Same(camera, again), "the written camera reads back different values:\n" + written);
  return 0;
}
