#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <map>
#include <opencv2/core/types.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace semap::perception {

// A calibration file that cannot be used; the message names the file and the key.
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The text of a KITTI calibration file (calib_cam_to_cam.txt, calib_velo_to_cam.txt): one
// `key: values...` entry per line. Values stay text until a caller asks for numbers, so entries
// such as `calib_time: 09-Jan-2012 13:57:47` are carried without being understood.
class KittiCalibText {
 public:
  // `name` (the file path for files) starts every error message. Throws CalibrationError for a
  // line without `key:` or a key given twice.
  KittiCalibText(std::string_view text, std::string name);
  static KittiCalibText read(const std::filesystem::path& path);

  const std::string& name() const { return name_; }
  bool contains(std::string_view key) const { return entries_.find(key) != entries_.end(); }

  // Exactly `count` finite numbers under `key`; throws CalibrationError naming the file and the
  // key when it is missing, has another count or a value that is not a number.
  std::vector<double> numbers(std::string_view key, std::size_t count) const;

  // A matrix stored row by row, as KITTI does.
  template <int Rows, int Cols>
  Eigen::Matrix<double, Rows, Cols> matrix(std::string_view key) const {
    const std::vector<double> v = numbers(key, static_cast<std::size_t>(Rows * Cols));
    // Eigen allows a row-major layout only for matrices with more than one column.
    constexpr int kLayout = Cols == 1 ? Eigen::ColMajor : Eigen::RowMajor;
    return Eigen::Map<const Eigen::Matrix<double, Rows, Cols, kLayout>>(v.data());
  }

  // The rigid transform of a `R:` (3x3, row by row) and `T:` (3) pair, as calib_velo_to_cam.txt
  // (camera 0 from Velodyne) and calib_imu_to_velo.txt (Velodyne from IMU) store it.
  Eigen::Isometry3d rigid_transform() const {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = matrix<3, 3>("R");
    t.translation() = matrix<3, 1>("T");
    return t;
  }

  // An image size stored as two numbers `width height` (S_rect_xx), positive whole pixels.
  cv::Size image_size(std::string_view key) const;

 private:
  [[noreturn]] void fail(std::string_view key, const std::string& what) const;

  std::string name_;
  std::map<std::string, std::string, std::less<>> entries_;
};

}  // namespace semap::perception
