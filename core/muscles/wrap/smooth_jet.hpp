#pragma once
// The smooth wrap model of one surface over Jet numbers with arbitrary seeds (issue 22): what the
// composition of several surfaces on one segment (core/muscles/wrap/smooth_composite.hpp) needs
// of each surface, with the inputs carrying derivatives the caller chose (the fixed point's
// unknowns, or the segment's ends and both surfaces' poses). The construction is smooth.cpp's
// own (smoothSetup / smoothEval); this only exposes it. No input checks: an end inside the surface
// fades to the straight path (the end-point fade), as the composition wants for its inner points.
#include <memory>

#include "core/geometry/dual.hpp"
#include "core/geometry/wrap_surface.hpp"

namespace redmax {

/// One surface's smooth model on the segment p1 -> p2 (surface frame), over Jet<N>.
template <int N>
class SmoothWrapJetSegment {
 public:
  using J = detail::Jet<N>;
  using V = detail::V3<J>;
  /// width: the penetration band (m; <= 0: 0.05 times the surface size, as SmoothWrapOptions)
  SmoothWrapJetSegment(const WrapSurface& surface, const V& p1, const V& p2, double width);
  ~SmoothWrapJetSegment();
  SmoothWrapJetSegment(SmoothWrapJetSegment&&) noexcept;
  SmoothWrapJetSegment& operator=(SmoothWrapJetSegment&&) noexcept;

  J weight;   ///< blend weight w of the wrapped path (0: straight)
  J length;   ///< the blended length L_straight + w (L_wrapped - L_straight)
  J lead;     ///< wrapped path: |p1 r1| + arc, the arc length where it leaves the surface (0 when w = 0)
  V r1, r2;   ///< wrapped path's tangent points (surface frame; p1 and p2 when w = 0)
  /// the blended point at fraction alpha of the segment (surface frame)
  V point(const J& alpha) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The default band (m) for `surface` when options width <= 0 (0.05 of its size).
double smoothWrapWidth(const WrapSurface& surface, double width);

}  // namespace redmax
