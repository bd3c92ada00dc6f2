#include "semap/perception/stereo_calibration.hpp"

#include <algorithm>
#include <initializer_list>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/persistence.hpp>
#include <stdexcept>
#include <string>

namespace semap::perception {

namespace {

// Reads the keys of one FileStorage file; every error names the file and the key.
class YamlReader {
 public:
  explicit YamlReader(const std::filesystem::path& path) : name_(path.string()) {
    try {
      fs_.open(name_, cv::FileStorage::READ);
    } catch (const cv::Exception& e) {
      throw CalibrationError(name_ + ": not an OpenCV FileStorage file: " + e.msg);
    }
    if (!fs_.isOpened()) throw CalibrationError(name_ + ": cannot open");
  }

  // A rows x cols matrix as CV_64F.
  cv::Mat matrix(const char* key, int rows, int cols) {
    cv::Mat m;
    try {
      fs_[key] >> m;
    } catch (const cv::Exception&) {
      fail(key, "not a matrix");
    }
    if (m.empty()) fail(key, "missing or empty");
    if (m.rows != rows || m.cols != cols || m.channels() != 1) {
      fail(key, "expected " + std::to_string(rows) + "x" + std::to_string(cols) + ", got " +
                    std::to_string(m.rows) + "x" + std::to_string(m.cols));
    }
    return as_double(key, m);
  }

  // A row or column of one of `lengths` values, returned as a column.
  cv::Mat vector(const char* key, std::initializer_list<int> lengths) {
    cv::Mat m;
    try {
      fs_[key] >> m;
    } catch (const cv::Exception&) {
      fail(key, "not a matrix");
    }
    if (m.empty()) fail(key, "missing or empty");
    const int n = static_cast<int>(m.total());
    if ((m.rows != 1 && m.cols != 1) || m.channels() != 1 ||
        std::find(lengths.begin(), lengths.end(), n) == lengths.end()) {
      std::string expected;
      for (const int length : lengths) {
        if (!expected.empty()) expected += '/';
        expected += std::to_string(length);
      }
      fail(key, "expected a vector of " + expected + " values, got " + std::to_string(m.rows) +
                    "x" + std::to_string(m.cols));
    }
    return as_double(key, m.reshape(1, n));
  }

  int positive_int(const char* key) {
    const cv::FileNode node = fs_[key];
    if (node.empty() || !node.isInt()) fail(key, "missing or not an integer");
    const int v = static_cast<int>(node);
    if (v < 1 || v > (1 << 15)) fail(key, "must be in [1, 32768], got " + std::to_string(v));
    return v;
  }

  [[noreturn]] void fail(const char* key, const std::string& what) const {
    throw CalibrationError(name_ + ": key '" + key + "': " + what);
  }

 private:
  cv::Mat as_double(const char* key, const cv::Mat& m) const {
    cv::Mat d;
    m.convertTo(d, CV_64F);
    if (!cv::checkRange(d)) fail(key, "not finite");
    return d;
  }

  std::string name_;
  cv::FileStorage fs_;
};

// fx, fy, cx, cy of a 3x4 (or 3x3) projection matrix.
template <typename Projection>
PinholeIntrinsics intrinsics_of(const Projection& p, cv::Size size) {
  PinholeIntrinsics k;
  k.width = size.width;
  k.height = size.height;
  k.fx = static_cast<float>(p(0, 0));
  k.fy = static_cast<float>(p(1, 1));
  k.cx = static_cast<float>(p(0, 2));
  k.cy = static_cast<float>(p(1, 2));
  return k;
}

}  // namespace

StereoCalibration StereoCalibration::from_opencv_yaml(const std::filesystem::path& path) {
  YamlReader yaml(path);
  const cv::Mat m1 = yaml.matrix("M1", 3, 3);
  // OpenCV's distortion models have 4, 5, 8, 12 or 14 coefficients.
  const cv::Mat d1 = yaml.vector("D1", {4, 5, 8, 12, 14});
  const cv::Mat m2 = yaml.matrix("M2", 3, 3);
  const cv::Mat d2 = yaml.vector("D2", {4, 5, 8, 12, 14});
  const cv::Mat r = yaml.matrix("R", 3, 3);
  const cv::Mat t = yaml.vector("T", {3});
  StereoCalibration calib;
  calib.half_size = cv::Size(yaml.positive_int("image_width"), yaml.positive_int("image_height"));

  cv::Mat r1, r2, p1, p2, q;
  try {
    cv::stereoRectify(m1, d1, m2, d2, calib.half_size, r, t, r1, r2, p1, p2, q,
                      cv::CALIB_ZERO_DISPARITY, 0.0, calib.half_size);
  } catch (const cv::Exception& e) {
    throw CalibrationError(path.string() + ": cv::stereoRectify rejects M1 D1 M2 D2 R T: " + e.msg);
  }
  // For a horizontal rig P2[0,3] = -f B; a vertical one puts the baseline in P2[1,3] instead.
  const double f = p1.at<double>(0, 0);
  const double baseline = -p2.at<double>(0, 3) / f;
  if (!(baseline > 0.0) || p2.at<double>(1, 3) != 0.0) {
    yaml.fail("T", "the right camera must be to the right of the left one (T.x < 0)");
  }
  calib.rectified = intrinsics_of(cv::Mat_<double>(p1), calib.half_size);
  calib.baseline_m = static_cast<float>(baseline);
  Eigen::Matrix3f r1_eigen;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r1_eigen(i, j) = static_cast<float>(r1.at<double>(i, j));
  }
  // R1 takes unrectified left points into the rectified frame.
  calib.left_from_rectified = r1_eigen.transpose();
  cv::initUndistortRectifyMap(m1, d1, r1, p1, calib.half_size, CV_16SC2, calib.left_map1,
                              calib.left_map2);
  cv::initUndistortRectifyMap(m2, d2, r2, p2, calib.half_size, CV_16SC2, calib.right_map1,
                              calib.right_map2);
  return calib;
}

StereoCalibration StereoCalibration::from_kitti(const KittiCalibText& cam_to_cam, int left_camera,
                                                int right_camera) {
  const auto key = [](const char* prefix, int camera) {
    if (camera < 0 || camera > 3) {
      throw std::invalid_argument("KITTI camera index must be 0..3, got " + std::to_string(camera));
    }
    return std::string(prefix) + "_0" + std::to_string(camera);
  };
  const std::string left_key = key("P_rect", left_camera);
  const std::string right_key = key("P_rect", right_camera);
  const Eigen::Matrix<double, 3, 4> pl = cam_to_cam.matrix<3, 4>(left_key);
  const Eigen::Matrix<double, 3, 4> pr = cam_to_cam.matrix<3, 4>(right_key);
  // A rectified pair shares its intrinsics; only the baseline term differs.
  const Eigen::Matrix3d kl = pl.leftCols<3>();
  const Eigen::Matrix3d kr = pr.leftCols<3>();
  if (!(kl - kr).isZero(1e-3) || !(pl(0, 0) > 0.0) || !(pl(1, 1) > 0.0)) {
    throw CalibrationError(cam_to_cam.name() + ": key '" + right_key + "': not rectified with " +
                           left_key + " (different intrinsics)");
  }
  const double baseline = (pl(0, 3) - pr(0, 3)) / pl(0, 0);
  if (!(baseline > 0.0)) {
    throw CalibrationError(cam_to_cam.name() + ": key '" + right_key +
                           "': camera is not to the right of " + left_key);
  }
  StereoCalibration calib;
  calib.half_size = cam_to_cam.image_size(key("S_rect", left_camera));
  calib.rectified = intrinsics_of(pl, calib.half_size);
  calib.baseline_m = static_cast<float>(baseline);
  return calib;
}

StereoCalibration StereoCalibration::load_kitti(const std::filesystem::path& cam_to_cam,
                                                int left_camera, int right_camera) {
  return from_kitti(KittiCalibText::read(cam_to_cam), left_camera, right_camera);
}

}  // namespace semap::perception
