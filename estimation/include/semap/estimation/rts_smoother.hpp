#pragma once

#include <Eigen/Cholesky>
#include <span>
#include <vector>

namespace semap::estimation {

// Rauch-Tung-Striebel smoothing of a Kalman filter's forward pass (docs/estimation.md,
// "Smoothing the first seconds"), on any state space with a retraction: `Space` gives
//   State, Vector (error) and Covariance types,
//   Space::plus(x, d)  = x (+) d, the state moved by an error d,
//   Space::minus(y, x) = y (-) x, the error that moves x to y (plus(x, minus(y, x)) = y).
// On a vector space these are + and -, and the pass is the textbook RTS.
//
// The forward filter, from step k to k + 1 with transition Phi_k of the error and noise Q_k:
//   x_{k+1|k} = f(x_{k|k}),   P_{k+1|k} = Phi_k P_{k|k} Phi_k^T + Q_k,                   (1)
// then the measurements of step k + 1 turn x_{k+1|k}, P_{k+1|k} into x_{k+1|k+1}, P_{k+1|k+1}.
// The backward pass, from x_{N|N} = x_{N|N}, P_{N|N} down to k = 0:
//   G_k     = P_{k|k} Phi_k^T P_{k+1|k}^-1,                                               (2)
//   x_{k|N} = x_{k|k} (+) G_k (x_{k+1|N} (-) x_{k+1|k}),                                  (3)
//   P_{k|N} = P_{k|k} + G_k (P_{k+1|N} - P_{k+1|k}) G_k^T.                                (4)
// Only P_{k+1|k}, Phi_k and the two estimates of each step are needed: the filter's
// measurements and noise enter through them.
template <class Space>
struct RtsStep {
  typename Space::State predicted;  // x_{k|k-1}; for k = 0 the first filtered state
  typename Space::Covariance predicted_covariance;
  typename Space::State filtered;  // x_{k|k}
  typename Space::Covariance filtered_covariance;
  // Phi_{k-1}, the error transition from step k - 1 to this one (unused for k = 0).
  typename Space::Covariance transition;
};

template <class Space>
struct RtsEstimate {
  typename Space::State state;            // x_{k|N}
  typename Space::Covariance covariance;  // P_{k|N}
};

// The smoothed estimates of every step, oldest first.
template <class Space>
std::vector<RtsEstimate<Space>> rts_smooth(std::span<const RtsStep<Space>> steps) {
  std::vector<RtsEstimate<Space>> out(steps.size());
  if (steps.empty()) return out;
  out.back() = {steps.back().filtered, steps.back().filtered_covariance};
  for (std::size_t k = steps.size() - 1; k-- > 0;) {
    const RtsStep<Space>& now = steps[k];
    const RtsStep<Space>& next = steps[k + 1];
    // (2) as G^T = P_{k+1|k}^-1 Phi_k P_{k|k}, both covariances symmetric.
    const typename Space::Covariance gain = next.predicted_covariance.ldlt()
                                                .solve(next.transition * now.filtered_covariance)
                                                .transpose();
    const typename Space::Vector correction =
        gain * Space::minus(out[k + 1].state, next.predicted);  // (3)
    out[k].state = Space::plus(now.filtered, correction);
    typename Space::Covariance p =  // (4)
        now.filtered_covariance +
        gain * (out[k + 1].covariance - next.predicted_covariance) * gain.transpose();
    out[k].covariance = 0.5 * (p + p.transpose());
  }
  return out;
}

// The vector space R^N, where (3) is x_{k|k} + G_k (x_{k+1|N} - x_{k+1|k}).
template <int N>
struct EuclideanSpace {
  using State = Eigen::Matrix<double, N, 1>;
  using Vector = State;
  using Covariance = Eigen::Matrix<double, N, N>;
  static State plus(const State& x, const Vector& d) { return x + d; }
  static Vector minus(const State& y, const State& x) { return y - x; }
};

}  // namespace semap::estimation
