#pragma once
// OpenSim's SmoothSegmentedFunction: a C2-continuous curve made of quintic Bezier segments
// (each a "corner" between two points with given slopes), linear beyond its ends, evaluated by
// solving x(u) = x for the Bezier parameter u of the segment that holds x, then y(u) and
// dy/dx = y'(u) / x'(u) [Millard 2013, Appendix; OpenSim's SegmentedQuinticBezierToolkit].
#include <array>
#include <string>
#include <vector>

namespace redmax::hill {

/// one quintic Bezier segment: control points (x_k, y_k), k = 0..5
struct QuinticBezierSegment {
  std::array<double, 6> x{}, y{};
};

/// The corner between (x0, y0) with slope dydx0 and (x1, y1) with slope dydx1: the two tangent
/// lines meet at C; the inner control points sit at fraction `c` (0..1, already scaled by
/// scaleCurviness) of the way from each end to C, doubled: P0, P0 + c(C - P0) twice,
/// P1 + c(C - P1) twice, P1. Throws MuscleModelError when C does not make a C-shaped corner.
QuinticBezierSegment quinticBezierCorner(double x0, double y0, double dydx0, double x1, double y1,
                                         double dydx1, double c);

/// OpenSim's curviness scaling: 0.1 + 0.8 curviness
inline double scaleCurviness(double curviness) { return 0.1 + 0.8 * curviness; }

/// d^order B / du^order of the quintic Bezier with control values p at u in [0, 1] (order 0..2)
double quinticBezier(double u, const std::array<double, 6>& p, int order = 0);

class SmoothSegmentedFunction {
 public:
  SmoothSegmentedFunction() = default;
  /// segments in increasing x; beyond x0 the line y0 + dydx0 (x - x0), beyond x1 likewise
  SmoothSegmentedFunction(std::vector<QuinticBezierSegment> segments, double x0, double x1, double y0,
                          double y1, double dydx0, double dydx1);

  double value(double x) const;
  double derivative(double x) const;
  /// both, with one solve for u
  void valueAndDerivative(double x, double& y, double& dydx) const;

  const std::vector<QuinticBezierSegment>& segments() const { return segments_; }
  double x0() const { return x0_; }
  double x1() const { return x1_; }

 private:
  std::vector<QuinticBezierSegment> segments_;
  double x0_ = 0, x1_ = 0, y0_ = 0, y1_ = 0, dydx0_ = 0, dydx1_ = 0;
};

// ---- OpenSim's SmoothSegmentedFunctionFactory curves (arguments as OpenSim names them) ------
// Each throws MuscleParameterError naming the property (as in MuscleParameters) it refuses.

/// ActiveForceLengthCurve: lce0 < lce1 < lce2 = 1 < lce3, shoulder value ylow, plateau slope dydx
SmoothSegmentedFunction makeFiberActiveForceLengthCurve(double x0, double x1, double x2, double x3,
                                                        double ylow, double dydx, double curviness);
/// ForceVelocityCurve (fv of normalized velocity in [-1, 1])
SmoothSegmentedFunction makeFiberForceVelocityCurve(double fmaxE, double dydxC, double dydxNearC,
                                                    double dydxIso, double dydxE, double dydxNearE,
                                                    double concCurviness, double eccCurviness);
/// ForceVelocityInverseCurve: the same corners with x and y swapped (needs dydxC, dydxE > 0)
SmoothSegmentedFunction makeFiberForceVelocityInverseCurve(double fmaxE, double dydxC, double dydxNearC,
                                                           double dydxIso, double dydxE, double dydxNearE,
                                                           double concCurviness, double eccCurviness);
/// FiberForceLengthCurve: zero up to 1 + eZero, 1 at 1 + eIso with slope kIso, kLow near zero
SmoothSegmentedFunction makeFiberForceLengthCurve(double eZero, double eIso, double kLow, double kIso,
                                                  double curviness);
/// TendonForceLengthCurve: zero up to 1, 1 at 1 + eIso with slope kIso, toe up to force fToe
SmoothSegmentedFunction makeTendonForceLengthCurve(double eIso, double kIso, double fToe, double curviness);

}  // namespace redmax::hill
