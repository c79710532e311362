// effects/lightning.h — lightning paths by Laplacian growth on a 2-D grid or a 3-D voxel grid.
//
// Source: seed 002 (Yun & Yoon, "Physically Inspired Fast Lightning Rendering", KAIST 2016),
// Niemeyer et al. 1984 (DBM), Kim & Lin 2004 (DBM with CG), Kim, Sewall, Sud & Lin 2007
// (point charges). Digest: docs/effects.md section 1.
//
// Grid: width x height cells, cell (x, y) covers [x, x+1] x [y, y+1]; x right, y down.
// 8-neighbourhood by default, 4 on request (classic DBM). The bolt grows one cell per step
// from `start`; candidate i is picked with
// probability p_i = Phi_i^eta / sum_j Phi_j^eta (seed 002 eqn 2), computed in log space.
// A segment ends when the bolt touches (is a neighbour of) its target; the target joins the bolt.
// Several targets make chain lightning: each later segment grows from the previous target.
// A target region (the ground, a roof, a mesh's voxels) ends the strike on whichever of its
// cells the bolt touches first: DBM holds the whole region at Phi = 1; fast and charges aim
// at the region's cell nearest to the segment's start (by A*), and fast's P (eqn 5) is the
// distance to the region's nearest cell.
//
// Methods (how Phi is obtained):
//   kFast    seed 002 eqns 4-8: Phi_i = a^G / (B * N * P), candidates live `lifetime` steps.
//            Defaults calibrated to DBM (calibrate(), below); the paper's literal a = 2,
//            lifetime 4 are kPaper*.
//   kDbm     converged Laplace solve every step (bolt, obstacles and border Phi = 0, target
//            Phi = 1). Solver kCapacitance (the default): the exact solution by the
//            capacitance-matrix method, one Cholesky row per step, while the fixed cells are
//            few (2-D: about 4.5 sqrt(cells) up to 256^2, at most 1024, and 6 sqrt(cells)
//            past it, at most 8192; 3-D: 1024, on grids up to about 80^3); past that, MGPCG.
//            kMgpcg: multigrid-preconditioned CG warm-started to `tolerance`; kCg: plain CG
//            (the baseline of Kim & Lin 2004 and of seed 002's comparison).
//   kCharges Kim et al. 2007: incremental point-charge potential, no linear solve.
// Obstacles are cells the bolt may not enter. With guide kAstar (kAuto: when obstacles exist)
// the fast and charges methods follow the turning points of an 8-connected A* path (seed
// 002 section 3.2); DBM needs no guide (Laplace solutions have no local minima).
//
// 3-D (Params::depth > 0): voxels (x, y, z), x right, y down, z away; 26 neighbours by default
// (6 on request); kFast's B sums 1/r over the voxels of the shell around the grid and the
// obstacle voxels (a Barnes-Hut octree); kDbm solves the 7-point Laplacian; A* moves over the
// same neighbourhood. kCharges is 2-D only. docs/effects.md section 1.7.
//
// Errors: start/target outside the grid or inside an obstacle, start == target, a start or
// target inside the target region, an unreachable target or region -> kUnsatisfiable naming
// the field; exhausting the step budget ->
// kLimitExceeded. Deterministic: same Params -> same Bolt, bit for bit.
// Thread-safety: reentrant; the boundary-map cache is internally synchronised.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "effects/common.h"

#include "effects/export.h"
#include "effects/parallel.h"

EFFECTS_API_BEGIN
namespace effects::lightning {

// ---- The request -------------------------------------------------------------------
struct Cell {
  int x = 0, y = 0, z = 0;  // z: 3-D grids only (0 in 2-D)
  bool operator==(const Cell& o) const { return x == o.x && y == o.y && z == o.z; }
};

enum class Method { kFast, kDbm, kCharges };
enum class Solver { kMgpcg, kCg, kCapacitance };
enum class Guide { kAuto, kAstar, kNone };

// Seed 002's literal eqn 8 and lifetime (the `paper` variant): bolts thinner than DBM's.
inline constexpr double kPaperAxisGrowth = 2.0;
inline constexpr int kPaperLifetime = 4;
// The calibration (effects/lightning/calibration.cpp, printed in docs/lightning-calibration.md
// "Current table"): for each grid and eta, the base per cell, the radius eqn 6's N is counted
// within and the candidates' lifetime that make the fast method's bolts meet DBM's fractal
// dimension, cell count and branch tips. Below 256^2 in the 8-neighbourhood (2-D) the base is:
inline constexpr double kCalibratedAxisGrowth8 = 1.2;
// Cells one bolt may add (Params::maxSteps, Limits::maxGrowthSteps).
inline constexpr size_t kDefaultMaxGrowthSteps = 2'000'000;

// How far grow() has come, handed to Params::progress.
struct Progress {
  size_t cells = 0;   // the bolt's cells so far
  size_t steps = 0;   // growth steps so far
  // The share of the way done, in [0, 1]: over the targets (and the region) in turn, how close
  // the bolt's nearest cell has come to the current one, against the segment's start. Growth
  // slows as the bolt grows (each DBM step solves a larger problem), so time is not linear in it.
  double fraction = 0;
};
// Called while a bolt grows, at most every kProgressIntervalMs (not at all for a bolt that takes
// less); returning false stops grow(), which returns an Error of kind kCancelled.
using ProgressCallback = std::function<bool(const Progress&)>;
inline constexpr double kProgressIntervalMs = 50;

struct Params {
  int width = 128, height = 128;
  int depth = 0;                   // 0: a 2-D grid; >= 3: a 3-D grid of width*height*depth voxels
  std::vector<uint8_t> obstacles;  // empty, or width*height(*depth) flags (x fastest, then y,
                                   // then z; nonzero = blocked)
  Cell start{64, 0};
  std::vector<Cell> targets{{64, 127}};  // may be empty when targetRegion is given
  std::vector<uint8_t> targetRegion;     // empty, or flags like obstacles: after the targets (if
                                         // any) the bolt grows until it touches one of these
                                         // cells (those inside an obstacle do not count)
  Method method = Method::kFast;
  double eta = 2.0;         // [0, 50]; seed 002: 2..3 looks like lightning
  int lifetime = 0;         // kFast: steps a candidate lives; 0 = forever (seed 002 uses 4)
  double axisGrowth = kCalibratedAxisGrowth8;  // kFast: base of eqn 8's 2^G per cell, in [1, 64]
                                               // (calibrate() sets it and the lifetime that meet
                                               // DBM's D, cells and tips for the grid and eta,
                                               // as the server does)
  double screening = 1.0;   // kFast: exponent of eqn 6's N (Phi ~ 1 / N^screening), in [0, 8]
  int screeningRadius = 0;  // kFast, 2-D: N counts the bolt cells within this Chebyshev radius,
                            // in [0, 7]; 1: eqn 6's adjacent cells; 0: calibratedScreeningRadius()
  double chargesEta = 0;    // kCharges: the power of Kim et al.'s potential, in [0, 50]; 0 =
                            // calibratedChargesEta() (the `paper` variant sends eta itself)
  int neighbourhood = 8;    // 8 (diagonals too) or 4: which cells are candidates, which
                            // touch a target, how the A* guide moves, N's range (eqn 6);
                            // in 3-D 26 (faces, edges and corners) or 6 (faces)
  Guide guide = Guide::kAuto;
  Solver solver = Solver::kCapacitance;  // kDbm
  double tolerance = 1e-6;  // kDbm, iterative solvers: the candidates' relative accuracy (each step
                            // solves to ||r|| / ||b|| <= tolerance x their largest Phi), in [1e-12, 1e-1]
  uint64_t seed = 1;
  size_t maxSteps = kDefaultMaxGrowthSteps;  // growth budget (cells added)
  bool measureError = false;    // per-step TV distance to the converged Laplace distribution
  ProgressCallback progress;    // optional: progress reports and cancellation (Progress)
  Parallel* parallel = nullptr;  // kDbm from 512^2 (64^3) cells: where the iterative solver may split
                                 // its fine level's loops (the same bolt on any threads); null: this thread
};

[[nodiscard]] std::optional<Error> validate(const Params& p);

// ---- The bolt ----------------------------------------------------------------------
struct Node {
  Cell cell;
  int parent = -1;  // index into Bolt::nodes; -1 for the start
  int step = 0;     // growth step at which the cell joined (0 = start)
};

struct Bolt {
  int depth = 0;                 // the grid's (0: 2-D)
  std::vector<Node> nodes;       // in growth order
  std::vector<int> mainChannel;  // node indices, start -> last target
  std::vector<Cell> guide;       // waypoints used (empty without a guide)
  Stats stats;                   // counters: steps, candidatesMax, solverIterations, residual,
                                 // boundaryMapMs, guideMs ...; error: mean TV (measureError)
};

Result<Bolt> grow(const Params& params);

// ---- The calibration: the fast method's defaults -----------------------------------
double calibratedAxisGrowth(const Params& p);
// eqn 6's N counts the bolt cells within this Chebyshev radius (1: the adjacent cells, as in
// the paper); the calibration's radius for 2-D fast, else 1.
int calibratedScreeningRadius(const Params& p);
// Steps a fast candidate lives (0 = forever): the calibration's lifetime.
int calibratedLifetime(const Params& p);
// Sets the calibrated defaults the server uses, from one look at the obstacles: axisGrowth and
// lifetime (the radius follows from screeningRadius 0 when the bolt grows).
void calibrate(Params& p);
// `variant: "paper"`: the source papers' constants over whatever calibrate() set: eqn 8's base
// (kPaperAxisGrowth) and lifetime (kPaperLifetime), eqn 6's N over the adjacent cells, and
// Kim et al.'s power at DBM's eta.
void usePaperConstants(Params& p);
// The radius grow() counts N within: Params::screeningRadius when set, else the calibrated
// one; 1 for every method but 2-D fast.
int screeningRadius(const Params& p);
// kCharges: the power of Kim et al.'s normalised potential (their dimension parameter) that
// gives DBM's dimension at the grid's eta (the calibration's charges law). Used with the
// parameter itself at eta, their potential is far less screened than DBM's.
double calibratedChargesEta(const Params& p);

// ---- Names and limits --------------------------------------------------------------
// The names the HTTP API spells ("fast", "dbm", "charges"; "mgpcg", "cg", "capacitance";
// "auto", "astar", "none"), both ways: the one mapping the server and the C API use. parse*
// give nullopt for any other name.
const char* toString(Method m);
const char* toString(Solver s);
const char* toString(Guide g);
std::optional<Method> parseMethod(std::string_view name);
std::optional<Solver> parseSolver(std::string_view name);
std::optional<Guide> parseGuide(std::string_view name);
// The neighbourhood a request that names none grows in: 8 in 2-D, 26 in 3-D.
int defaultNeighbourhood(int depth);

// Bounds on one bolt's work. The defaults are the service's (its flags raise or lower them);
// the C API holds untrusted parameters to them.
struct Limits {
  size_t maxGridCells = size_t(4096) * 4096;         // any method: width x height (x depth)
  size_t maxSolverGridCells = size_t(256) * 256;     // kDbm and kCharges in 2-D: each step costs O(cells)
  size_t maxSolverVolumeCells = size_t(64) * 64 * 64;  // kDbm and kCharges in 3-D
  size_t maxGrowthSteps = kDefaultMaxGrowthSteps;     // cells added per bolt
  size_t maxTargets = 64;                            // chain lightning's targets (the contract's)
  // What raises each grid bound, named in checkLimits' message (the server's flags); empty: nothing.
  std::string_view gridKnob, solverGridKnob, solverVolumeKnob;
};
// kLimitExceeded at "/grid" when the grid's cells exceed maxGridCells, or, for kDbm and
// kCharges, the solver's bound (2-D or 3-D); the message names the cells, the bound and its knob.
[[nodiscard]] std::optional<Error> checkLimits(const Params& p, const Limits& limits);
// Working memory kDbm's capacitance solver may take on a grid (depth 0: 2-D) beyond the
// iterative solver's (its Cholesky factor, rows of G, the grid's table of G), for admission
// estimates; 0 where the grid is too large for it (3-D past about 80^3: MGPCG alone).
size_t capacitanceBytes(int width, int height, int depth = 0);

// ---- Measures ----------------------------------------------------------------------
// Box-counting dimension of a set of cells (seed 002's quality figure): for box sizes
// 1, 2, 4, ... up to a quarter of the grid, the minimum box count over four grid offsets;
// D is the slope of log N against log(1/s) fitted over the straightest run of >= 4 scales.
double fractalDimension(const std::vector<Cell>& cells, int width, int height);
// The same in 3-D: cubes of side 1, 2, 4, ... up to a quarter of the smallest side, the
// minimum over eight offsets.
double fractalDimension(const std::vector<Cell>& cells, int width, int height, int depth);

// What a player sees of a bolt, for comparing methods over seeds: cells, tips (cells nothing
// grew from), branch points (cells two or more grew from) and the box-counting dimension D on
// the bolt's grid.
struct BoltShape {
  double cells = 0, tips = 0, dimension = 0, branchPoints = 0;
};
BoltShape shapeOf(const Bolt& bolt, int width, int height, int depth = 0);
// Two sets of bolts (a method's, a reference's; each over seeds) compared on their mean cells,
// tips and D, each difference in units of its standard error (Welch: sqrt(s_a^2/n_a +
// s_r^2/n_r)); `worst` is the largest. About 2 or less: indistinguishable at these seeds.
struct ShapeDistance {
  double cells = 0, tips = 0, dimension = 0, worst = 0;
  BoltShape mean, refMean;
};
ShapeDistance shapeDistance(const std::vector<BoltShape>& method, const std::vector<BoltShape>& reference);

// Conservative voxelisation (3-D obstacles from meshes): sets obstacles[(z*height + y)*width
// + x] for every voxel [x, x+1] x [y, y+1] x [z, z+1] that a triangle touches (separating-axis
// test). positions: x, y, z per vertex in voxel units; indices: three per triangle, each
// < positions.size() / 3; coordinates must be finite. Returns the voxels tested.
size_t voxelizeTriangles(int width, int height, int depth, const std::vector<double>& positions,
                         const std::vector<uint32_t>& indices, std::vector<uint8_t>& obstacles);
// The voxels voxelizeTriangles would test (the triangles' clipped bounding boxes), to refuse
// a mesh before the work.
size_t voxelizationWork(int width, int height, int depth, const std::vector<double>& positions,
                        const std::vector<uint32_t>& indices);

// ---- Shape for renderers (seed 002 section 3.3) -------------------------------------
struct ShapeParams {
  double jitter = 1.0;           // [0, 1]: vertices move up to jitter/2 cells from cell centres
  uint64_t jitterSeed = 1;       // separate from the growth seed: same bolt, other jitter
  double branchWidth = 1.0;      // main channel = 2 x branch width (Reed & Wyvill)
  double branchIntensity = 0.6;  // branch brightness where it leaves the main channel (main: 1)
  double branchFalloff = 16.0;   // cells of tree distance over which branch brightness falls by e
};

struct Vertex {
  float x = 0, y = 0, z = 0;  // grid units, jittered inside the cell (z: 3-D bolts)
  int step = 0;            // growth step of the cell (animate the leader by step, the return
                           // stroke along the main channel from the last step back)
  float intensity = 1.0f;  // 1 on the main channel, fading along branches
  int node = 0;            // index into Bolt::nodes
};

struct Polyline {
  bool main = false;  // channel: main (start -> target) or branch
  float width = 1.0f;
  std::vector<Vertex> vertices;  // a branch starts at the vertex it leaves its parent from
};

// Main channel first, then branches, each following its longest continuation.
std::vector<Polyline> polylines(const Bolt& bolt, const ShapeParams& shape);

// ---- Strike timeline: when each vertex lights and how bright the channels are -------------
// A cloud-to-ground flash in physical units (Uman, "The Lightning Discharge"; Rakov & Uman,
// "Lightning: Physics and Effects"): a stepped leader advances from the start in steps of
// ~50 m separated by 20-50 us pauses, along every branch at once; when it touches the target
// the leader stops (branch tips it had not reached stay dark) and a return stroke runs back up
// the main channel at ~1/3 c, flashing the branches once; 3-4 strokes 40-60 ms apart re-light
// the main channel (each dart leader follows the old channel); the channel flickers between
// strokes and its glow fades over ~100 ms. Deterministic from `seed`; the bolt's shape is not
// touched, so the same bolt can be animated many ways. Times are game seconds = physical
// seconds * timeScale. Docs: docs/effects.md section 1.6.
struct TimelineParams {
  uint64_t seed = 1;                 // the animation seed (pauses, stroke count and spacing, flicker)
  double timeScale = 1;              // game seconds per physical second, (0, 1e6]
  double cellSize = 25;              // metres per grid cell
  double leaderStep = 50;            // metres per leader step
  double pauseMinUs = 20, pauseMaxUs = 50;
  double returnStrokeSpeed = 1e8;    // m/s (~c/3)
  int strokes = 0;                   // return strokes; 0 = 3 or 4 at random
  double intervalMinMs = 40, intervalMaxMs = 60;
  double flashMs = 8;                // decay time of each stroke's flash
  double glowMs = 35;                // decay time of the channel's glow (gone after ~100 ms)
  double leaderBrightness = 0.3;     // the leader's glow relative to the first stroke's peak
  double flicker = 0.25;             // relative brightness noise of the glow between strokes
};

[[nodiscard]] std::optional<Error> validate(const TimelineParams& p);

// Brightness of the three channel classes over time; clients interpolate linearly.
struct Keyframe {
  double t = 0;
  float leader = 0;    // vertices the leader has reached and no stroke has yet
  float main = 0;      // the main channel after the first stroke reached the vertex
  float branches = 0;  // branch vertices after the first stroke reached them (first stroke only)
};

struct Stroke {
  double t = 0;     // when the return stroke starts at the target
  float peak = 1;   // its peak brightness (the first: 1)
};

struct Timeline {
  // Per polyline, per vertex (parallel to polylines()): when the leader reaches the vertex,
  // and how long after a stroke starts that stroke reaches it. Along a polyline both grow
  // monotonically in the leader's direction.
  std::vector<std::vector<double>> leader, strokeDelay;
  double connect = 0;   // the leader touches the target: it stops, the first stroke starts
  double duration = 0;  // every channel dark from here
  std::vector<Stroke> strokes;
  std::vector<Keyframe> keyframes;
};

// The strike over `bolt` as grown by grow(), with `lines` its polylines(bolt, ...). Errors
// (kInvalidArgument): params outside validate()'s ranges (their fields); "/bolt" for a bolt
// grow() did not make (no nodes or main channel, a node before its parent, a main channel
// naming no node); "/lines" for polylines naming a node the bolt does not have.
[[nodiscard]] Result<Timeline> timeline(const Bolt& bolt, const std::vector<Polyline>& lines,
                                        const TimelineParams& params);

// The keyframe channels at time t (linear between keyframes, 0 outside).
Keyframe channelsAt(const Timeline& tl, double t);

// A vertex's brightness at time t (0 before the leader reaches it or if it never does,
// multiplied by its intensity), as a client would compute it from the answer.
double vertexBrightness(const Timeline& tl, const std::vector<Polyline>& lines, size_t line, size_t vertex, double t);

// The bolt as an eye sees it over one frame [t0, t1]: each polyline cut to the vertices the
// leader has reached by t1, each vertex's intensity the highest brightness it had during the
// frame (a flash shorter than a frame is not lost between frames); unlit polylines left out.
std::vector<Polyline> exposure(const Timeline& tl, const std::vector<Polyline>& lines, double t0, double t1);

}  // namespace effects::lightning
EFFECTS_API_END
