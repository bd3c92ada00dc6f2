#include "semap/estimation/geodesy.hpp"

#include <GeographicLib/LocalCartesian.hpp>

namespace semap::estimation {

struct LocalEnu::Impl {
  GeographicLib::LocalCartesian frame;
};

LocalEnu::LocalEnu(const Geodetic& origin)
    : origin_(origin),
      impl_(std::make_unique<Impl>(Impl{GeographicLib::LocalCartesian(
          origin.latitude_deg, origin.longitude_deg, origin.altitude_m)})) {}

LocalEnu::~LocalEnu() = default;

LocalEnu::LocalEnu(const LocalEnu& other)
    : origin_(other.origin_), impl_(std::make_unique<Impl>(*other.impl_)) {}

LocalEnu& LocalEnu::operator=(const LocalEnu& other) {
  if (this != &other) {
    origin_ = other.origin_;
    impl_ = std::make_unique<Impl>(*other.impl_);
  }
  return *this;
}

Eigen::Vector3d LocalEnu::to_enu(const Geodetic& point) const {
  Eigen::Vector3d enu;
  impl_->frame.Forward(point.latitude_deg, point.longitude_deg, point.altitude_m, enu.x(), enu.y(),
                       enu.z());
  return enu;
}

Geodetic LocalEnu::to_geodetic(const Eigen::Vector3d& enu) const {
  Geodetic g;
  impl_->frame.Reverse(enu.x(), enu.y(), enu.z(), g.latitude_deg, g.longitude_deg, g.altitude_m);
  return g;
}

}  // namespace semap::estimation
