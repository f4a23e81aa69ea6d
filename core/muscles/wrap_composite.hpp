#pragma once
// Type III mass points on paths where several wrap objects can act on one segment, with the
// smooth model (issue 22): each wrapped segment goes through the composition of its surfaces
// (core/muscles/wrap/smooth_composite.hpp; one surface is the single-surface smooth model), the
// rest is wrap_muscle.hpp's segment construction (Eulerian coordinates over the segments'
// lengths, EOL on straight segments). Which wraps act on a segment: each wrap object takes the
// segment of its range whose straight line penetrates it most (calcSegmentWraps' rule without its
// limit of one wrap per segment). The chain rule goes through the composition's inputs u = (ends,
// every surface's rotation entries and origin, the fraction): dR/dq_j = [J_om e_j] R, so
// J_ar = (dx/du) (du/dq) and Jdot_ar = d/dt(dx/du) (du/dq) + (dx/du) d/dt(du/dq), exact.
#include <vector>

#include "core/muscles/wrap_muscle.hpp"

namespace redmax {

/// True when two active wrap objects' ranges share a segment (OpenSim may apply both to it):
/// the muscle then goes through the composition (smooth model only).
bool hasSharedWrapSegments(const Muscle& muscle);

/// For each segment between consecutive active points (world positions x_w), the wrap objects
/// (indices into muscle.path.wraps) acting on it, in path.wraps order; E_ws: each wrap surface's
/// world pose (one per wrap object). A wrap skips segments with an end inside its surface
/// (except origin -> surface -> insertion).
std::vector<std::vector<int>> calcSegmentWrapSets(const Muscle& muscle, const std::vector<int>& active,
                                                  const std::vector<Vec3>& x_w, const std::vector<Mat4>& E_ws);

/// calcWrapMassPointsOnSurfaces for such muscles: surfaces[w] for every wrap object (their motion
/// in mk's columns), mk after the path stage. Fills what calcWrapMassPoints fills. Throws
/// MuscleError naming the muscle where the composition cannot be evaluated.
void calcCompositeWrapMassPointsOnSurfaces(const Muscle& muscle, const std::vector<WrapSurfaceMotion>& surfaces,
                                           MuscleKinematics& mk);

/// The smooth model's path length of such a muscle (straight segments plus each wrapped segment's
/// composed length) from its active points' world positions and the surfaces' world poses.
double calcCompositePathLength(const Muscle& muscle, const std::vector<int>& active, const std::vector<Vec3>& x_w,
                               const std::vector<Mat4>& E_ws);

}  // namespace redmax
