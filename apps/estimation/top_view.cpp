#include "top_view.hpp"

#include <algorithm>
#include <array>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "semap/estimation/geodesy.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::apps {

namespace {
constexpr int kSize = 1000;
constexpr int kMargin = 40;
const std::array<cv::Scalar, 3> kColours = {cv::Scalar(200, 80, 0), cv::Scalar(0, 0, 220),
                                            cv::Scalar(0, 160, 220)};
}  // namespace

void write_top_view(const std::filesystem::path& path, const estimation::DriveData& data,
                    const std::vector<estimation::NamedEvaluationRun>& runs,
                    const std::string& truth_label) {
  const estimation::LocalEnu enu(data.origin);
  std::vector<Eigen::Vector3d> fixes;
  for (const auto& f : data.gnss) {
    fixes.push_back(enu.to_enu({f.latitude_deg, f.longitude_deg, f.altitude_m}));
  }
  double min_x = 1e18, max_x = -1e18, min_y = 1e18, max_y = -1e18;
  auto grow = [&](const Eigen::Vector3d& p) {
    min_x = std::min(min_x, p.x());
    max_x = std::max(max_x, p.x());
    min_y = std::min(min_y, p.y());
    max_y = std::max(max_y, p.y());
  };
  for (const auto& t : data.truth) grow(t.state.position);
  for (const auto& r : runs) {
    for (const auto& s : r.run.samples) grow(s.estimate.position);
  }
  const double span = std::max({max_x - min_x, max_y - min_y, 1.0});
  const double scale = (kSize - 2 * kMargin) / span;
  auto pixel = [&](const Eigen::Vector3d& p) {
    return cv::Point(kMargin + static_cast<int>((p.x() - min_x) * scale),
                     kSize - kMargin - static_cast<int>((p.y() - min_y) * scale));
  };
  cv::Mat image(kSize, kSize, CV_8UC3, cv::Scalar(255, 255, 255));
  for (const auto& f : fixes) cv::circle(image, pixel(f), 1, cv::Scalar(180, 180, 180), -1);
  std::vector<cv::Point> line;
  for (const auto& t : data.truth) line.push_back(pixel(t.state.position));
  cv::polylines(image, line, false, cv::Scalar(0, 150, 0), 2, cv::LINE_AA);
  int legend_y = 25;
  cv::putText(image, truth_label, {10, legend_y}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 150, 0}, 2);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    line.clear();
    for (const auto& s : runs[i].run.samples) line.push_back(pixel(s.estimate.position));
    const cv::Scalar colour = kColours[i % kColours.size()];
    cv::polylines(image, line, false, colour, 1, cv::LINE_AA);
    legend_y += 22;
    cv::putText(image, runs[i].name, {10, legend_y}, cv::FONT_HERSHEY_SIMPLEX, 0.6, colour, 2);
  }
  cv::putText(image, "GNSS fixes (grey); " + std::to_string(static_cast<int>(span)) + " m across",
              {10, kSize - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {90, 90, 90}, 1);
  if (!cv::imwrite(path.string(), image)) {
    throw std::runtime_error(path.string() + ": cannot write PNG");
  }
}

void write_csv(const std::filesystem::path& path,
               const std::vector<estimation::NamedEvaluationRun>& runs) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path.string() + ": cannot open for writing");
  constexpr double kDeg = 180.0 / std::numbers::pi;
  out << "filter,t,true_x,true_y,true_z,est_x,est_y,est_z,true_yaw_deg,est_yaw_deg,"
         "heading_error_deg,nees\n";
  out.precision(10);
  for (const auto& r : runs) {
    for (const auto& s : r.run.samples) {
      out << r.name << ',' << s.t << ',' << s.truth.position.x() << ',' << s.truth.position.y()
          << ',' << s.truth.position.z() << ',' << s.estimate.position.x() << ','
          << s.estimate.position.y() << ',' << s.estimate.position.z() << ','
          << estimation::yaw_of(s.truth.rotation) * kDeg << ','
          << estimation::yaw_of(s.estimate.rotation) * kDeg << ',' << s.heading_error_deg << ','
          << s.nees << '\n';
    }
  }
  if (!out) throw std::runtime_error(path.string() + ": write failed");
}

}  // namespace semap::apps
