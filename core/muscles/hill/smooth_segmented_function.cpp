#include "core/muscles/hill/smooth_segmented_function.hpp"

#include <cmath>
#include <limits>

#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
const double kRootEps = std::sqrt(kEps);
const double kSignificantReal = std::pow(kEps, 0.875);
constexpr double kUTol = kEps * 1e2;  // OpenSim's UTOL on |x(u) - x|

[[noreturn]] void bad(const std::string& property, const std::string& what) {
  throw MuscleParameterError(property, property + " " + what);
}

void checkCurviness(const std::string& property, double c) {
  if (!(c >= 0 && c <= 1)) bad(property, "must be between 0 and 1");
}

}  // namespace

QuinticBezierSegment quinticBezierCorner(double x0, double y0, double dydx0, double x1, double y1,
                                         double dydx1, double c) {
  // where the two end tangents cross (the midpoint when they are parallel)
  double xC = std::abs(dydx0 - dydx1) > kRootEps ? (y1 - y0 - x1 * dydx1 + x0 * dydx0) / (dydx0 - dydx1)
                                                  : (x1 + x0) / 2;
  const double yC = (xC - x1) * dydx1 + y1;
  // the corner must be C-shaped: the chord longer than either leg
  const double a = (xC - x0) * (xC - x0) + (yC - y0) * (yC - y0);
  const double b = (xC - x1) * (xC - x1) + (yC - y1) * (yC - y1);
  const double chord = (x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0);
  if (!(chord > a && chord > b))
    throw MuscleModelError("quintic Bezier corner: the end slopes do not make a C-shaped corner");
  QuinticBezierSegment s;
  const double x0m = x0 + c * (xC - x0), y0m = y0 + c * (yC - y0);
  const double x1m = x1 + c * (xC - x1), y1m = y1 + c * (yC - y1);
  s.x = {x0, x0m, x0m, x1m, x1m, x1};
  s.y = {y0, y0m, y0m, y1m, y1m, y1};
  return s;
}

double quinticBezier(double u, const std::array<double, 6>& p, int order) {
  // Bernstein form of B and of its first two derivatives (differences of the control values), the
  // powers by products: std::pow here was 80% of a Millard forward run (gait10dof18musc, perf)
  const double v = 1 - u;
  const double u2 = u * u, u3 = u2 * u, v2 = v * v, v3 = v2 * v;
  if (order == 0) {
    const double u4 = u2 * u2, v4 = v2 * v2;
    return v4 * v * p[0] + 5 * v4 * u * p[1] + 10 * v3 * u2 * p[2] + 10 * v2 * u3 * p[3] + 5 * v * u4 * p[4] +
           u4 * u * p[5];
  }
  if (order == 1) {
    const double u4 = u2 * u2, v4 = v2 * v2;
    return 5 * (v4 * (p[1] - p[0]) + 4 * v3 * u * (p[2] - p[1]) + 6 * v2 * u2 * (p[3] - p[2]) +
                4 * v * u3 * (p[4] - p[3]) + u4 * (p[5] - p[4]));
  }
  return 20 * (v3 * (p[2] - 2 * p[1] + p[0]) + 3 * v2 * u * (p[3] - 2 * p[2] + p[1]) +
               3 * v * u2 * (p[4] - 2 * p[3] + p[2]) + u3 * (p[5] - 2 * p[4] + p[3]));
}

SmoothSegmentedFunction::SmoothSegmentedFunction(std::vector<QuinticBezierSegment> segments, double x0,
                                                 double x1, double y0, double y1, double dydx0, double dydx1)
    : segments_(std::move(segments)), x0_(x0), x1_(x1), y0_(y0), y1_(y1), dydx0_(dydx0), dydx1_(dydx1) {}

void SmoothSegmentedFunction::valueAndDerivative(double x, double& y, double& dydx) const {
  // linear beyond the ends
  if (x < x0_) {
    y = y0_ + dydx0_ * (x - x0_);
    dydx = dydx0_;
    return;
  }
  if (x > x1_) {
    y = y1_ + dydx1_ * (x - x1_);
    dydx = dydx1_;
    return;
  }
  // the segment whose x range holds x (OpenSim's calcIndex)
  size_t idx = segments_.size();
  for (size_t i = 0; i < segments_.size(); ++i)
    if (x >= segments_[i].x[0] && x < segments_[i].x[5]) {
      idx = i;
      break;
    }
  if (idx == segments_.size()) {
    if (!segments_.empty() && x == segments_.back().x[5]) {
      idx = segments_.size() - 1;
    } else {
      throw MuscleModelError("smooth segmented function: x = " + std::to_string(x) + " is in no segment");
    }
  }
  const QuinticBezierSegment& s = segments_[idx];
  // u with x(u) = x: x(u) increases on a corner segment; bisect to a bracket, then Newton
  double lo = 0, hi = 1;
  for (int k = 0; k < 12; ++k) {
    const double mid = 0.5 * (lo + hi);
    (quinticBezier(mid, s.x) < x ? lo : hi) = mid;
  }
  double u = 0.5 * (lo + hi);
  double f = quinticBezier(u, s.x) - x;
  for (int it = 0; it < 50 && std::abs(f) > kUTol; ++it) {
    const double df = quinticBezier(u, s.x, 1);
    double un = df != 0 ? u - f / df : 0.5 * (lo + hi);
    if (!(un > lo && un < hi)) un = 0.5 * (lo + hi);  // keep Newton inside the bracket
    u = un;
    f = quinticBezier(u, s.x) - x;
    (f < 0 ? lo : hi) = u;
  }
  if (!(std::abs(f) <= kUTol))
    throw MuscleModelError("smooth segmented function: no Bezier parameter for x = " + std::to_string(x));
  y = quinticBezier(u, s.y);
  dydx = quinticBezier(u, s.y, 1) / quinticBezier(u, s.x, 1);
}

double SmoothSegmentedFunction::value(double x) const {
  double y, d;
  valueAndDerivative(x, y, d);
  return y;
}

double SmoothSegmentedFunction::derivative(double x) const {
  double y, d;
  valueAndDerivative(x, y, d);
  return d;
}

// ---------------------------------------------------------------------------------------------
// the curves (SmoothSegmentedFunctionFactory)

SmoothSegmentedFunction makeFiberActiveForceLengthCurve(double x0, double x1, double x2, double x3,
                                                        double ylow, double dydx, double curviness) {
  if (!(x0 >= 0)) bad("min_norm_active_fiber_length", "must be >= 0");
  if (!(x1 > x0 + kRootEps)) bad("transition_norm_fiber_length", "must exceed min_norm_active_fiber_length");
  if (!(x2 > x1 + kRootEps)) bad("transition_norm_fiber_length", "must be less than 1");
  if (!(x3 > x2 + kRootEps)) bad("max_norm_active_fiber_length", "must be greater than 1");
  if (!(ylow >= 0)) bad("minimum_value", "must be >= 0");
  const double upper = (1 - ylow) / (x2 - x1);
  if (!(dydx >= 0 && dydx < upper))
    bad("shallow_ascending_slope", "must be in [0, " + std::to_string(upper) + ")");
  checkCurviness("curviness", curviness);
  const double c = scaleCurviness(curviness);
  // five corners: rise from the minimum, shallow ascent, plateau at 1 (its corner widened by half
  // a sarcomere, 0.05 x2), descent, back to the minimum
  const double xDelta = 0.05 * x2;
  const double xs = x2 - xDelta;
  const double y0 = 0, dydx0 = 0;
  const double y1 = 1 - dydx * (xs - x1);
  const double dydx01 = 1.25 * (y1 - y0) / (x1 - x0);
  const double x01 = x0 + 0.5 * (x1 - x0), y01 = y0 + 0.5 * (y1 - y0);
  const double x1s = x1 + 0.5 * (xs - x1), y1s = y1 + 0.5 * (1 - y1), dydx1s = dydx;
  const double y2 = 1, dydx2 = 0, y3 = 0, dydx3 = 0;
  const double x23 = (x2 + xDelta) + 0.5 * (x3 - (x2 + xDelta)), y23 = y2 + 0.5 * (y3 - y2);
  const double dydx23 = (y3 - y2) / ((x3 - xDelta) - (x2 + xDelta));
  std::vector<QuinticBezierSegment> s = {
      quinticBezierCorner(x0, ylow, dydx0, x01, y01, dydx01, c),
      quinticBezierCorner(x01, y01, dydx01, x1s, y1s, dydx1s, c),
      quinticBezierCorner(x1s, y1s, dydx1s, x2, y2, dydx2, c),
      quinticBezierCorner(x2, y2, dydx2, x23, y23, dydx23, c),
      quinticBezierCorner(x23, y23, dydx23, x3, ylow, dydx3, c)};
  return SmoothSegmentedFunction(std::move(s), x0, x3, ylow, ylow, 0, 0);
}

namespace {
void checkForceVelocity(double fmaxE, double dydxC, double dydxNearC, double dydxIso, double dydxE,
                        double dydxNearE, double concCurviness, double eccCurviness, bool inverse) {
  if (!(fmaxE > 1.0)) bad("max_eccentric_velocity_force_multiplier", "must be greater than 1");
  if (inverse ? !(dydxC > kSignificantReal && dydxC < 1) : !(dydxC >= 0 && dydxC < 1))
    bad("concentric_slope_at_vmax", inverse ? "must be in (0, 1)" : "must be in [0, 1)");
  if (!(dydxNearC > dydxC && (inverse ? dydxNearC < 1 : dydxNearC <= 1)))
    bad("concentric_slope_near_vmax", "must be greater than concentric_slope_at_vmax and at most 1");
  if (!(dydxIso > 1)) bad("isometric_slope", "must be greater than 1");
  if (inverse ? !(dydxE > kSignificantReal && dydxE < fmaxE - 1) : !(dydxE >= 0 && dydxE < fmaxE - 1))
    bad("eccentric_slope_at_vmax", "must be in [0, max_eccentric_velocity_force_multiplier - 1)");
  if (!(dydxNearE >= dydxE && dydxNearE < fmaxE - 1))
    bad("eccentric_slope_near_vmax",
        "must be in [eccentric_slope_at_vmax, max_eccentric_velocity_force_multiplier - 1)");
  checkCurviness("concentric_curviness", concCurviness);
  checkCurviness("eccentric_curviness", eccCurviness);
}

// the four corners of the force-velocity curve: (-1, 0) to (-0.9, near) to (0, 1) to (0.9, near)
// to (1, fmaxE)
std::vector<QuinticBezierSegment> forceVelocityCorners(double fmaxE, double dydxC, double dydxNearC,
                                                       double dydxIso, double dydxE, double dydxNearE,
                                                       double concCurviness, double eccCurviness) {
  const double cC = scaleCurviness(concCurviness), cE = scaleCurviness(eccCurviness);
  const double xC = -1, yC = 0, xNearC = -0.9;
  const double yNearC = yC + 0.5 * dydxNearC * (xNearC - xC) + 0.5 * dydxC * (xNearC - xC);
  const double xIso = 0, yIso = 1, xE = 1, yE = fmaxE, xNearE = 0.9;
  const double yNearE = yE + 0.5 * dydxNearE * (xNearE - xE) + 0.5 * dydxE * (xNearE - xE);
  return {quinticBezierCorner(xC, yC, dydxC, xNearC, yNearC, dydxNearC, cC),
          quinticBezierCorner(xNearC, yNearC, dydxNearC, xIso, yIso, dydxIso, cC),
          quinticBezierCorner(xIso, yIso, dydxIso, xNearE, yNearE, dydxNearE, cE),
          quinticBezierCorner(xNearE, yNearE, dydxNearE, xE, yE, dydxE, cE)};
}
}  // namespace

SmoothSegmentedFunction makeFiberForceVelocityCurve(double fmaxE, double dydxC, double dydxNearC,
                                                    double dydxIso, double dydxE, double dydxNearE,
                                                    double concCurviness, double eccCurviness) {
  checkForceVelocity(fmaxE, dydxC, dydxNearC, dydxIso, dydxE, dydxNearE, concCurviness, eccCurviness, false);
  return SmoothSegmentedFunction(
      forceVelocityCorners(fmaxE, dydxC, dydxNearC, dydxIso, dydxE, dydxNearE, concCurviness, eccCurviness),
      -1, 1, 0, fmaxE, dydxC, dydxE);
}

SmoothSegmentedFunction makeFiberForceVelocityInverseCurve(double fmaxE, double dydxC, double dydxNearC,
                                                           double dydxIso, double dydxE, double dydxNearE,
                                                           double concCurviness, double eccCurviness) {
  checkForceVelocity(fmaxE, dydxC, dydxNearC, dydxIso, dydxE, dydxNearE, concCurviness, eccCurviness, true);
  auto s = forceVelocityCorners(fmaxE, dydxC, dydxNearC, dydxIso, dydxE, dydxNearE, concCurviness, eccCurviness);
  for (auto& seg : s) std::swap(seg.x, seg.y);
  return SmoothSegmentedFunction(std::move(s), 0, fmaxE, -1, 1, 1 / dydxC, 1 / dydxE);
}

SmoothSegmentedFunction makeFiberForceLengthCurve(double eZero, double eIso, double kLow, double kIso,
                                                  double curviness) {
  if (!(eIso > eZero)) bad("strain_at_one_norm_force", "must be greater than strain_at_zero_force");
  if (!(kIso > 1.0 / (eIso - eZero)))
    bad("stiffness_at_one_norm_force", "must be greater than 1/(strain_at_one_norm_force - strain_at_zero_force)");
  if (!(kLow > 0.0 && kLow < 1 / (eIso - eZero)))
    bad("stiffness_at_low_force", "must be in (0, 1/(strain_at_one_norm_force - strain_at_zero_force))");
  checkCurviness("curviness", curviness);
  const double c = scaleCurviness(curviness);
  const double xZero = 1 + eZero, yZero = 0, xIso = 1 + eIso, yIso = 1;
  const double deltaX = std::min(0.1 * (1.0 / kIso), 0.1 * (xIso - xZero));
  const double xLow = xZero + deltaX, xfoot = xZero + 0.5 * (xLow - xZero), yfoot = 0;
  const double yLow = yfoot + kLow * (xLow - xfoot);
  std::vector<QuinticBezierSegment> s = {quinticBezierCorner(xZero, yZero, 0, xLow, yLow, kLow, c),
                                         quinticBezierCorner(xLow, yLow, kLow, xIso, yIso, kIso, c)};
  return SmoothSegmentedFunction(std::move(s), xZero, xIso, yZero, yIso, 0.0, kIso);
}

SmoothSegmentedFunction makeTendonForceLengthCurve(double eIso, double kIso, double fToe, double curviness) {
  if (!(eIso > 0)) bad("strain_at_one_norm_force", "must be greater than 0");
  if (!(fToe > 0 && fToe < 1)) bad("norm_force_at_toe_end", "must be in (0, 1)");
  if (!(kIso > 1 / eIso)) bad("stiffness_at_one_norm_force", "must be greater than 1/strain_at_one_norm_force");
  checkCurviness("curviness", curviness);
  const double c = scaleCurviness(curviness);
  const double x0 = 1.0, y0 = 0, dydx0 = 0;
  const double xIso = 1.0 + eIso, yIso = 1, dydxIso = kIso;
  // the toe ends on the line through (xIso, 1) with slope kIso, at force fToe
  const double yToe = fToe, xToe = (yToe - 1) / kIso + xIso;
  const double xFoot = 1.0 + (xToe - 1.0) / 10.0, yFoot = 0;
  const double yToeMid = yToe * 0.5, xToeMid = (yToeMid - yIso) / kIso + xIso;
  const double dydxToeMid = (yToeMid - yFoot) / (xToeMid - xFoot);
  const double xToeCtrl = xFoot + 0.5 * (xToeMid - xFoot);
  const double yToeCtrl = yFoot + dydxToeMid * (xToeCtrl - xFoot);
  std::vector<QuinticBezierSegment> s = {
      quinticBezierCorner(x0, y0, dydx0, xToeCtrl, yToeCtrl, dydxToeMid, c),
      quinticBezierCorner(xToeCtrl, yToeCtrl, dydxToeMid, xToe, yToe, dydxIso, c)};
  return SmoothSegmentedFunction(std::move(s), x0, xToe, y0, yToe, dydx0, dydxIso);
}

}  // namespace redmax::hill
