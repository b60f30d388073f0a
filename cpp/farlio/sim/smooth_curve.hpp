#pragma once
// A C2 function of one variable through knots (x_k, y_k): between consecutive knots it moves
// from y_k to y_{k+1} along the quintic smoothstep 10u^3 - 15u^4 + 6u^5, whose first and
// second derivatives vanish at both ends. Two equal consecutive values give a plateau. Outside
// the knots the function is constant. Value, derivatives and the integral are all analytic.
#include <vector>

namespace farlio::sim {

class SmoothCurve {
 public:
  SmoothCurve() = default;
  /// Knots must have strictly increasing x (throws std::invalid_argument otherwise).
  SmoothCurve(std::vector<double> x, std::vector<double> y);

  /// Appends a knot after the last one (x must increase).
  void add_knot(double x, double y);

  [[nodiscard]] double value(double x) const;
  [[nodiscard]] double derivative(double x) const;
  [[nodiscard]] double second_derivative(double x) const;
  /// Integral from the first knot to x (negative for x before it).
  [[nodiscard]] double integral(double x) const;

  [[nodiscard]] bool empty() const { return x_.empty(); }
  [[nodiscard]] double first_x() const { return x_.front(); }
  [[nodiscard]] double last_x() const { return x_.back(); }
  [[nodiscard]] double last_y() const { return y_.back(); }
  [[nodiscard]] const std::vector<double>& knots_x() const { return x_; }
  [[nodiscard]] const std::vector<double>& knots_y() const { return y_; }

 private:
  /// Index k of the interval [x_k, x_{k+1}) holding x; -1 before the first knot, n-1 after the last.
  [[nodiscard]] long interval(double x) const;

  std::vector<double> x_, y_;
  std::vector<double> cumulative_;  ///< integral from x_0 to x_k
};

}  // namespace farlio::sim
