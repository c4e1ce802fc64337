// Scan-line (ring) recovery for clouds that carry no usable `ring` field, so that BI* gets every
// physical beam of the LiDAR as one scan line.
//
// Four sources, tried in this order by ensureRings(): the sensor's ring field, the storage order of
// a KITTI .bin sweep, a per-beam model fitted to the cloud itself (any point order: shuffled, in
// image-row order, cropped to the camera's view) and, last, elevation binning.
//
// The beam model: a spinning LiDAR's beam i leaves from a point h_i above (or below) the origin
// on the spin axis, at elevation theta_i, so each of its points satisfies
//   z = r tan(theta_i) + h_i,   r = hypot(x, y),   i.e.   z / r = tan(theta_i) + h_i / r:
// a straight line in (1 / r, z / r). Elevation alone cannot separate beams whose origins differ
// (HDL-64E: h = 0.12 m for the lower block, 0.20 m for the upper one; at r = 5 m that shifts the
// elevation by more than three beam spacings); the lines can. A LiDAR without scan lines
// (non-repetitive patterns such as Livox's rosette) has no such lines: the model then explains
// too few points, and ensureRings() falls back to elevation bands marked implausible, so that the
// node reports it (stats.ring_method "elevation", a warning) and BI* gets evenly spaced pseudo
// scan lines.
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

/// Recovers rings of a KITTI HDL-64E .bin sweep, stored laser by laser: a new laser starts where
/// the azimuth atan2(y, x) crosses 0 going up (counted only after the current laser has passed the
/// +-180 deg wrap, so azimuth jitter around 0 cannot split a laser). Writes ring 0.. into every
/// point in storage order (on KITTI ring 0 is the highest beam); non-finite points get the ring of
/// the points around them. Returns the number of rings (0 for an empty cloud).
int recoverRingsBySweepOrder(LidarCloud& cloud);

/// Recovers rings from the elevation angle atan2(z, hypot(x, y)) for clouds without a ring field
/// and not in sweep order, from sensors whose beams share one origin (VLS-128, Ouster, ...): the
/// sorted elevations are split into beams at the (at most num_rings - 1) widest gaps that are at
/// least `min_gap_deg` [deg] wide. Unlike uniform bins this follows non-uniform beam spacing
/// (VLS-128: 0.11 deg in the centre, several degrees at the edges) and does not invent beams that
/// returned nothing. Ring 0 is the lowest beam; non-finite points get -1. Returns the number of
/// rings found (<= num_rings). Throws std::invalid_argument for num_rings < 1 or min_gap_deg < 0.
int recoverRingsByElevation(LidarCloud& cloud, int num_rings, double min_gap_deg = 0.05);

/// Bands of elevation for a cloud without scan lines (non-repetitive patterns): the finite points
/// sorted by elevation atan2(z, hypot(x, y)) are cut into min(bands, points) bands of equal point
/// counts, ring 0 the lowest; non-finite points get -1. BI* then joins the points of each band as
/// a pseudo scan line. Returns the number of bands. Throws std::invalid_argument for bands < 1.
int recoverRingsByElevationBands(LidarCloud& cloud, int bands);

/// One beam of the beam model: its points satisfy z = r tan_elevation + offset, r = hypot(x, y).
struct BeamLine {
  double tan_elevation = 0.0;  ///< tan(theta_i), the beam's z / r far away
  double offset = 0.0;         ///< h_i [m], height of the beam's origin on the spin axis
  int points = 0;              ///< points given this beam
  double rms = 0.0;            ///< RMS residual of z / r on the beam's inliers (tan units)
};

/// The fraction of the points the beam lines must explain for plausible rings.
constexpr double kMinBeamModelExplained = 0.9;
/// Below this fraction explained the cloud has no scan lines (chance lines through points spread
/// evenly in elevation explain ~50 %: a quarter spacing on either side of each).
constexpr double kMinScanLineExplained = 0.7;

/// Outcome of recoverRingsByBeamModel().
struct BeamModel {
  std::vector<BeamLine> beams;  ///< ascending tan_elevation; ring i is beams[i]
  /// Fraction of the finite points that lie within a quarter of the beam spacing of their beam's
  /// line (1 for a clean spinning LiDAR; ~0.5 when points fill the elevations evenly).
  double explained = 0.0;
  std::string problem;  ///< empty when the cloud has scan lines, else why the model is not used
};

/// Recovers the physical beams of a spinning LiDAR from the cloud itself, independent of the point
/// order: finds the lines z / r = tan(theta_i) + h_i / r (see the file comment) with a Hough
/// transform over (h, tan theta), refines each by least squares on its inliers, and gives every
/// finite point the nearest beam. Assumes the cloud is in the sensor's frame: z along the spin
/// axis, the beam origins within 0.5 m of the frame's origin along it. Ring 0 is the beam with
/// the lowest elevation; non-finite points get -1. `problem` (rings still written) when fewer than
/// 2 or more than `max_beams` beams are found, or the lines explain fewer than
/// kMinBeamModelExplained of the points (no scan lines). Deterministic; the beams found do not
/// depend on the point order (the Hough's sample is chosen by a hash of the coordinates). Throws
/// std::invalid_argument for max_beams < 1.
BeamModel recoverRingsByBeamModel(LidarCloud& cloud, int max_beams);

/// True when every point has ring >= 0.
bool hasRings(const LidarCloud& cloud);

/// Where the rings of a sweep came from.
enum class RingSource {
  kField,       ///< the sensor's ring field, plausible as it was
  kSweepOrder,  ///< recoverRingsBySweepOrder (KITTI .bin / kitti2bag order)
  kBeamModel,   ///< recoverRingsByBeamModel (any order: shuffled, filtered, cropped)
  kElevation,   ///< recoverRingsByElevation
};
/// "ring_field", "sweep_order", "beam_model" or "elevation".
std::string ringSourceName(RingSource source);

/// The scan lines a cloud's rings number: the largest ring + 1 (0 when no point has a ring).
int countRings(const LidarCloud& cloud);

/// Outcome of ensureRings(): the method used, the rings it found, and why earlier methods were
/// passed over (empty when the first one was plausible).
struct RingRecovery {
  RingSource source = RingSource::kField;
  int rings = 0;          ///< distinct scan lines (max ring + 1)
  bool plausible = true;  ///< false: the rings used failed a check (said in `fallbacks`)
  std::string fallbacks;  ///< e.g. "ring field: 1 ring for 120000 points; sweep order: ..."
};

/// Empty when the rings of `cloud` look like a real scan pattern, else what is wrong: fewer than
/// 2 rings for >= 100 points, more than `max_rings`, more than a quarter of the rings with fewer
/// than 5 points, or mean elevations per ring that are not (at least 80 % of neighbouring pairs)
/// monotonic in the ring index. Points with ring < 0 are ignored.
std::string ringPlausibilityProblem(const LidarCloud& cloud, int max_rings);

/// Makes sure every point has a plausible ring, trying in order: the ring field (when
/// `has_ring_field` and plausible), the sweep order rule of the offline path (not when more than
/// 1 % of the points step back in azimuth within a ring: no sweep order), the beam model
/// (recoverRingsByBeamModel) and elevation binning into at most `num_rings` beams (num_rings, times
/// 2, is also the most rings accepted from the others: a sensor with more beams than configured is
/// still recognised). Every recovery is checked with ringPlausibilityProblem(); the result says
/// which method was used and why the others were not. Beam lines that explain between
/// kMinScanLineExplained and kMinBeamModelExplained of the points (a VoxelGrid's output) are used,
/// with plausible false. When the beam model finds no scan lines (its lines explain less than
/// kMinScanLineExplained of >= 100 points: a non-repetitive pattern such as Livox's), the rings
/// are num_rings elevation bands of equal point counts (recoverRingsByElevationBands), with source
/// kElevation and plausible false. Throws std::invalid_argument for num_rings < 1.
RingRecovery ensureRings(LidarCloud& cloud, bool has_ring_field, int num_rings);

}  // namespace lidar_stereo_fusion
