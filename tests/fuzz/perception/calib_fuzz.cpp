// Feeds arbitrary bytes to the KITTI calibration parser: text before the first NUL byte is
// calib_cam_to_cam.txt, text after it calib_velo_to_cam.txt. Parsing must either give finite
// calibrations or throw CalibrationError, never crash, hang or over-allocate.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "semap/perception/lidar_projection.hpp"
#include "semap/perception/stereo_calibration.hpp"

using semap::perception::CalibrationError;
using semap::perception::KittiCalibText;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t split = bytes.find('\0');
  const std::string_view cam = bytes.substr(0, split);
  const std::string_view velo = split == std::string_view::npos ? "" : bytes.substr(split + 1);
  try {
    const KittiCalibText cam_text(cam, "cam_to_cam");
    try {
      const auto stereo = semap::perception::StereoCalibration::from_kitti(cam_text);
      if (!(stereo.baseline_m > 0.0f) || stereo.half_size.area() <= 0) std::abort();
    } catch (const CalibrationError&) {
    }
    const auto calib = semap::perception::KittiCameraCalibration::from_text(
        cam_text, KittiCalibText(velo, "velo_to_cam"));
    if (!calib.p_rect.allFinite() || !calib.r_rect.allFinite() ||
        !calib.cam_from_lidar.matrix().allFinite() || calib.image_size.area() <= 0) {
      std::abort();
    }
  } catch (const CalibrationError&) {
  }
  return 0;
}
