// Every constant that tunes the river simulation core (river surface, stream function,
// obstacles), in one place. Units are metres unless a comment says otherwise.
#pragma once

#include <cstddef>
#include <cstdint>

namespace siviflow {

// --- Stream function (paper eq. 2.1-2.3, algorithms.md §1.1) -------------------------------
// Shepard power p: 1 gives plug flow, 1.5 (Neyret's value) a centreline speed of 1.5 Q/W.
inline constexpr float kDefaultShepardPower = 1.5f;
// Default search radius s as a multiple of the widest section: s >= 2-3 W keeps the profile
// close to the pure power law (algorithms.md §6.2 shows how s near W sharpens it).
inline constexpr float kDefaultSearchRadiusFactor = 3.0f;

// Beyond a tongue's tip (where two arms meet), the streamline parting them relaxes from the tip
// to where the plain field puts it as exp(-a sqrt(x / W) - b x / W), x the distance from the tip
// and W the river's width there, and not past kTipReachWidths W: fitted to a fine-grid Laplace
// solution of a Y (river_network_test). The square root is the tip's corner singularity, the
// linear term the channel's decay.
inline constexpr double kTipRelaxationRoot = 1.5;
inline constexpr double kTipRelaxationLinear = 1.0;
inline constexpr double kTipReachWidths = 1.5;

// Islands' psi (island_circulation.h): each cluster of islands is solved on the sections within
// this many widest-section widths of it, to this relative residual, in at most this many steps.
inline constexpr double kIslandSolveMarginWidths = 0.5;
inline constexpr double kIslandSolveTolerance = 1e-6;
inline constexpr int kIslandSolveMaxIterations = 20000;

// --- Input limits (reliability.md §5 rows 8 and 17) -----------------------------------------
// Caps that keep every internal 32-bit index and every allocation sane before we allocate.
inline constexpr size_t kMaxRiverVertices = size_t{1} << 27;
inline constexpr size_t kMaxRiverTriangles = size_t{1} << 28;
// Islands (holes in the river mesh) take a 16-bit border index beside the two banks.
inline constexpr size_t kMaxRiverIslands = 65000;
// The procedural generator's islands: every terrain sample asks each, so they are few; and none
// so small that its half-size rounds to nothing.
inline constexpr size_t kMaxProceduralIslands = 256;
inline constexpr float kMinProceduralIslandSize = 0.01f;
// The procedural confluence's bed rises to its tongue (and past its tip) at this slope, m/m.
inline constexpr float kConfluenceShelfSlope = 0.8f;
// Obstacles are few (objects touching the water); polygons are footprints, not meshes.
inline constexpr size_t kMaxObstacles = 4096;
inline constexpr size_t kMaxPolygonPoints = 4096;
inline constexpr size_t kMaxObstacleKeys = 1u << 20;

// --- Geometry tolerances ----------------------------------------------------------------------
// A triangle is degenerate when 2*area / (longest edge)^2 falls below this (a sliver of about
// 6e-6 degrees): its normal, gradient and flow direction would be noise.
inline constexpr double kDegenerateTriangleRatio = 1e-7;
// A section is of zero width when narrower than this fraction of the mesh's bounding diagonal.
inline constexpr double kMinSectionWidthRelative = 1e-6;
// A section whose shore chord is within this fraction of vertical has no horizontal flow
// direction (the plane through the shores and the raised midpoint degenerates).
inline constexpr double kMinHorizontalChordRelative = 1e-6;
// A river network's corners (where an end meets a bank) are border vertices where the water's
// angle is below this; along a bank or an end it is about 180 degrees, at a corner about 90.
inline constexpr double kNetworkCornerMaxAngle = 0.75 * 3.14159265358979323846;

// --- Spatial grids (obstacle queries) ---------------------------------------------------------
// Grid cells in the XZ plane: about this many river vertices per cell on average, and never
// more cells than kMaxGridCellsPerVertex per vertex (a thin, long river over a huge box).
inline constexpr double kGridVerticesPerCell = 4.0;
inline constexpr double kMaxGridCellsPerVertex = 2.0;

}  // namespace siviflow
