#pragma once

#include <Eigen/Core>
#include <memory>

namespace semap::estimation {

// WGS84 geodetic coordinates.
struct Geodetic {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double altitude_m = 0.0;  // above the ellipsoid
};

// A local East-North-Up frame anchored at a geodetic point (GeographicLib::LocalCartesian).
class LocalEnu {
 public:
  explicit LocalEnu(const Geodetic& origin);
  ~LocalEnu();
  LocalEnu(const LocalEnu& other);
  LocalEnu& operator=(const LocalEnu& other);

  Eigen::Vector3d to_enu(const Geodetic& point) const;
  Geodetic to_geodetic(const Eigen::Vector3d& enu) const;
  const Geodetic& origin() const { return origin_; }

 private:
  struct Impl;
  Geodetic origin_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace semap::estimation
