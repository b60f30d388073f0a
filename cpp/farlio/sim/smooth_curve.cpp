#include "farlio/sim/smooth_curve.hpp"

#include <algorithm>
#include <stdexcept>

namespace farlio::sim {
namespace {
// Quintic smoothstep S(u) on [0, 1], its derivatives and its integral from 0.
double step(double u) { return u * u * u * (10.0 + u * (-15.0 + 6.0 * u)); }
double step_d1(double u) { return 30.0 * u * u * (1.0 + u * (-2.0 + u)); }
double step_d2(double u) { return 60.0 * u * (1.0 + u * (-3.0 + 2.0 * u)); }
double step_integral(double u) { return u * u * u * u * (2.5 + u * (-3.0 + u)); }
constexpr double kHalf = 0.5;  // integral of S over [0, 1]
}  // namespace

SmoothCurve::SmoothCurve(std::vector<double> x, std::vector<double> y) {
  if (x.size() != y.size() || x.empty()) throw std::invalid_argument("SmoothCurve: need equally many x and y knots");
  for (std::size_t k = 0; k < x.size(); ++k) add_knot(x[k], y[k]);
}

void SmoothCurve::add_knot(double x, double y) {
  if (!x_.empty() && !(x > x_.back())) throw std::invalid_argument("SmoothCurve: knots must strictly increase");
  if (x_.empty()) {
    cumulative_.push_back(0.0);
  } else {
    const double h = x - x_.back();
    cumulative_.push_back(cumulative_.back() + h * (y_.back() + kHalf * (y - y_.back())));
  }
  x_.push_back(x);
  y_.push_back(y);
}

long SmoothCurve::interval(double x) const {
  const auto it = std::upper_bound(x_.begin(), x_.end(), x);
  return static_cast<long>(it - x_.begin()) - 1;
}

double SmoothCurve::value(double x) const {
  const long k = interval(x);
  if (k < 0) return y_.front();
  if (k + 1 >= static_cast<long>(x_.size())) return y_.back();
  const auto i = static_cast<std::size_t>(k);
  const double u = (x - x_[i]) / (x_[i + 1] - x_[i]);
  return y_[i] + (y_[i + 1] - y_[i]) * step(u);
}

double SmoothCurve::derivative(double x) const {
  const long k = interval(x);
  if (k < 0 || k + 1 >= static_cast<long>(x_.size())) return 0.0;
  const auto i = static_cast<std::size_t>(k);
  const double h = x_[i + 1] - x_[i];
  return (y_[i + 1] - y_[i]) * step_d1((x - x_[i]) / h) / h;
}

double SmoothCurve::second_derivative(double x) const {
  const long k = interval(x);
  if (k < 0 || k + 1 >= static_cast<long>(x_.size())) return 0.0;
  const auto i = static_cast<std::size_t>(k);
  const double h = x_[i + 1] - x_[i];
  return (y_[i + 1] - y_[i]) * step_d2((x - x_[i]) / h) / (h * h);
}

double SmoothCurve::integral(double x) const {
  const long k = interval(x);
  if (k < 0) return y_.front() * (x - x_.front());
  const auto i = static_cast<std::size_t>(k);
  if (k + 1 >= static_cast<long>(x_.size())) return cumulative_.back() + y_.back() * (x - x_.back());
  const double h = x_[i + 1] - x_[i];
  const double u = (x - x_[i]) / h;
  return cumulative_[i] + h * (y_[i] * u + (y_[i + 1] - y_[i]) * step_integral(u));
}

}  // namespace farlio::sim
