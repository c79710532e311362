// The C API (effects/effects.h) over the C++ one: conversions of the C structs, the handles
// (C++ results kept whole, with flat copies where C wants arrays), and errors as values. No
// exception crosses the boundary: std::bad_alloc becomes EFFECTS_OUT_OF_MEMORY, anything else
// EFFECTS_INTERNAL.
#include "effects/effects.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "effects/bubble.h"
#include "effects/fog.h"
#include "effects/lightning.h"
#include "effects/tangents.h"
#include "effects/version.h"

struct effects_error {
  effects_status status;
  std::string field, message;
};

struct effects_fog_table {
  effects::fog::Table table;
};

struct effects_bolt {
  effects::lightning::Bolt bolt;
  int width = 0, height = 0;
  uint64_t seed = 1;
  std::vector<int32_t> cells, parents, steps, main;
};

struct effects_bolt_lines {
  struct Line {
    bool main = false;
    float width = 0;
    std::vector<float> points, intensities;
    std::vector<int32_t> steps;
    std::vector<double> leader, strokeDelay;
  };
  std::vector<Line> lines;
  double connect = 0, duration = 0;
};

struct effects_tangents {
  effects::tangents::Output out;
  std::vector<float> frames, normals;
};

struct effects_bubble_mesh {
  effects::bubble::Mesh mesh;
};

namespace {

// The error as a value; when even that cannot be allocated, OUT_OF_MEMORY with *error NULL.
effects_status fail(effects_error** error, effects_status status, const char* field, const char* message) noexcept {
  if (!error) return status;
  try {
    *error = new effects_error{status, field, message};
    return status;
  } catch (...) {
    *error = nullptr;
    return EFFECTS_OUT_OF_MEMORY;
  }
}
effects_status fail(effects_error** error, effects_status status, const std::string& field,
                    const std::string& message) noexcept {
  return fail(error, status, field.c_str(), message.c_str());
}

effects_status fail(effects_error** error, const effects::Error& e) noexcept {
  const effects_status status = e.kind == effects::ErrorKind::kUnsatisfiable   ? EFFECTS_UNSATISFIABLE
                                : e.kind == effects::ErrorKind::kLimitExceeded ? EFFECTS_LIMIT_EXCEEDED
                                                                               : EFFECTS_INVALID_ARGUMENT;
  return fail(error, status, e.field, e.message);
}

// Runs f (which returns an effects_status) with *error cleared first; exceptions become errors.
template <class F>
effects_status guarded(effects_error** error, F&& f) {
  if (error) *error = nullptr;
  try {
    return f();
  } catch (const std::bad_alloc&) {
    return fail(error, EFFECTS_OUT_OF_MEMORY, "", "out of memory");
  } catch (const std::exception& e) {
    return fail(error, EFFECTS_INTERNAL, "", e.what());  // fail() copies it without throwing out
  } catch (...) {
    return fail(error, EFFECTS_INTERNAL, "", "unknown exception");
  }
}

// A struct's size member: at least the size this library knows (older, shorter structs are
// not accepted yet: there are none).
bool sized(size_t given, size_t known) { return given >= known; }

glm::dvec3 vec(const double v[3]) { return {v[0], v[1], v[2]}; }

effects_status toFog(const effects_fog* c, effects::fog::Fog& f, effects_error** error) {
  namespace fg = effects::fog;
  if (!c) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "fog is NULL");
  if (!sized(c->size, sizeof(effects_fog)))
    return fail(error, EFFECTS_INVALID_ARGUMENT, "/size", "must be sizeof(effects_fog)");
  if (c->type < int32_t(EFFECTS_FOG_X3D_LINEAR) || c->type > int32_t(EFFECTS_FOG_ATMOSPHERIC))
    return fail(error, EFFECTS_INVALID_ARGUMENT, "/fogType", "is not an effects_fog_type");
  if (c->convention < int32_t(EFFECTS_FOG_EFFECTD) || c->convention > int32_t(EFFECTS_FOG_UNREAL))
    return fail(error, EFFECTS_INVALID_ARGUMENT, "/convention", "is not an effects_fog_convention");
  f.type = fg::FogType(int(c->type));
  f.convention = fg::Convention(int(c->convention));
  f.color = vec(c->color);
  f.visibilityRange = c->visibility_range;
  f.start = c->start;
  f.end = c->end;
  f.density = c->density;
  f.distanceCoefficient = c->distance_coefficient;
  f.peak = c->peak;
  f.heightFalloff = c->height_falloff;
  f.baseHeight = c->base_height;
  f.extinction = vec(c->extinction);
  f.inscattering = vec(c->inscattering);
  f.startDistance = c->start_distance;
  f.maxOpacity = c->max_opacity;
  f.cutoffDistance = c->cutoff_distance > 0 ? c->cutoff_distance : std::numeric_limits<double>::infinity();
  if (c->has_second_layer)
    f.secondLayer = fg::HeightLayer{c->second_density, c->second_height_falloff, c->second_base_height};
  if (c->has_directional) {
    fg::Directional d;
    d.color = vec(c->directional_color);
    d.direction = vec(c->directional_direction);
    d.g = c->directional_g;
    if (c->directional_exponent > 0) d.exponent = c->directional_exponent;
    d.startDistance = c->directional_start_distance;
    f.directional = d;
  }
  if (auto e = fg::validate(f)) return fail(error, *e);
  return EFFECTS_OK;
}

// The number of cells of a grid whose sides validate() has accepted.
size_t cellsOf(const effects::lightning::Params& p) {
  return size_t(p.width) * size_t(p.height) * size_t(std::max(p.depth, 1));
}

effects_status toBubble(const effects_bubble_params* c, effects::bubble::Params& p, effects::bubble::MeshOptions& o,
                        effects_error** error) {
  namespace bb = effects::bubble;
  if (!c) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "params is NULL");
  if (!sized(c->size, sizeof(effects_bubble_params)))
    return fail(error, EFFECTS_INVALID_ARGUMENT, "/size", "must be sizeof(effects_bubble_params)");
  p.n1 = c->n1, p.n2 = c->n2, p.deltaSpeed = c->delta_speed, p.betaSpeed = c->beta_speed;
  p.rimPower = c->rim_power, p.muSpeed = c->mu_speed;
  p.wobbleVariant = c->paper_wobble ? bb::WobbleVariant::kPaper : bb::WobbleVariant::kRelative;
  p.wobbleAmplitude = c->wobble_amplitude, p.wobbleFrequency = c->wobble_frequency;
  if (auto e = bb::validate(p)) return fail(error, *e);
  o.level = c->level;
  o.radius = c->radius;
  o.t = c->t;
  o.wobble = c->wobble != 0;
  if (!std::isfinite(c->t)) return fail(error, EFFECTS_INVALID_ARGUMENT, "/time", "must be finite");
  return EFFECTS_OK;
}

void fillBoltDefaults(effects_bolt_params* c);

char* copyString(const std::string& s) {
  char* out = static_cast<char*>(std::malloc(s.size() + 1));
  if (!out) throw std::bad_alloc();
  std::memcpy(out, s.c_str(), s.size() + 1);
  return out;
}

}  // namespace

extern "C" {

// ---- errors, versions, strings ----------------------------------------------------------------

effects_status effects_error_status(const effects_error* e) { return e ? e->status : EFFECTS_OK; }
const char* effects_error_field(const effects_error* e) { return e ? e->field.c_str() : ""; }
const char* effects_error_message(const effects_error* e) { return e ? e->message.c_str() : ""; }
void effects_error_free(effects_error* e) { delete e; }
const char* effects_version(void) { return EFFECTS_VERSION_STRING; }
int effects_c_api_version(void) { return EFFECTS_C_API_VERSION; }
void effects_string_free(char* s) { std::free(s); }

// ---- fog ---------------------------------------------------------------------------------------

void effects_fog_defaults(effects_fog* c) {
  if (!c) return;
  const effects::fog::Fog f;
  const effects::fog::HeightLayer layer;
  const effects::fog::Directional d;
  *c = effects_fog{};
  c->size = sizeof(effects_fog);
  c->type = int32_t(f.type);
  c->convention = int32_t(f.convention);
  for (int i = 0; i < 3; ++i) {
    c->color[i] = f.color[i];
    c->extinction[i] = f.extinction[i];
    c->inscattering[i] = f.inscattering[i];
    c->directional_color[i] = d.color[i];
    c->directional_direction[i] = d.direction[i];
  }
  c->visibility_range = f.visibilityRange;
  c->start = f.start;
  c->end = f.end;
  c->density = f.density;
  c->distance_coefficient = f.distanceCoefficient;
  c->peak = f.peak;
  c->height_falloff = f.heightFalloff;
  c->base_height = f.baseHeight;
  c->start_distance = f.startDistance;
  c->max_opacity = f.maxOpacity;
  c->cutoff_distance = 0;  // none
  c->second_density = layer.density;
  c->second_height_falloff = layer.heightFalloff;
  c->second_base_height = layer.baseHeight;
  c->directional_g = d.g;
  c->directional_exponent = 0;  // Henyey-Greenstein
  c->directional_start_distance = d.startDistance;
}

effects_status effects_fog_validate(const effects_fog* fog, effects_error** error) {
  return guarded(error, [&] {
    effects::fog::Fog f;
    return toFog(fog, f, error);
  });
}

effects_status effects_fog_factor(const effects_fog* fog, double originY, double dirY, double distance, double* out,
                                  effects_error** error) {
  return guarded(error, [&] {
    effects::fog::Fog f;
    if (effects_status s = toFog(fog, f, error)) return s;
    if (!out) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "f is NULL");
    if (!std::isfinite(originY) || !(dirY >= -1.0 && dirY <= 1.0) || !(distance >= 0.0) || !std::isfinite(distance))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/ray",
                  "origin_y finite, dir_y in [-1, 1], distance finite and >= 0");
    *out = effects::fog::factorAtElevation(f, originY, dirY, distance);
    return EFFECTS_OK;
  });
}

void effects_fog_table_options_defaults(effects_fog_table_options* c) {
  if (!c) return;
  const effects::fog::TableOptions o;
  *c = effects_fog_table_options{};
  c->size = sizeof(effects_fog_table_options);
  c->columns = 256;  // the service's default
  c->max_error = o.maxError;
  c->max_size = o.maxSize;
  c->elevations = o.elevations;
  c->camera_height = o.cameraHeight;
  c->layout = int32_t(o.layout == effects::fog::TableOptions::Layout::kWarped ? EFFECTS_FOG_LAYOUT_WARPED
                                                                              : EFFECTS_FOG_LAYOUT_LINEAR);
}

effects_status effects_fog_table_build(const effects_fog* fog, const effects_fog_table_options* c,
                                       effects_fog_table** table, effects_error** error) {
  return guarded(error, [&] {
    if (table) *table = nullptr;
    effects::fog::Fog f;
    if (effects_status s = toFog(fog, f, error)) return s;
    if (!c || !table) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "options or table is NULL");
    if (!sized(c->size, sizeof(effects_fog_table_options)))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/size", "must be sizeof(effects_fog_table_options)");
    if (c->layout != int32_t(EFFECTS_FOG_LAYOUT_LINEAR) && c->layout != int32_t(EFFECTS_FOG_LAYOUT_WARPED))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/layout", "is not an effects_fog_layout");
    if (c->max_size > effects::fog::kMaxTableEntries)
      return fail(error, EFFECTS_LIMIT_EXCEEDED, "/maxSize", "at most 2^24 entries (the contract's largest table)");
    if (c->columns > c->max_size || c->elevations > c->max_size)
      return fail(error, EFFECTS_LIMIT_EXCEEDED, "/size", "columns and elevations are each at most max_size");
    if (!std::isfinite(c->camera_height) || !std::isfinite(c->range_start) || !std::isfinite(c->range_end) ||
        !(c->max_error >= 0 && c->max_error <= 1))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/table",
                  "camera_height and the range must be finite, max_error in [0, 1]");
    effects::fog::TableOptions o;
    o.size = c->columns;
    o.maxError = c->max_error;
    o.maxSize = c->max_size;
    if (c->range_end > c->range_start) o.rangeStart = c->range_start, o.rangeEnd = c->range_end;
    o.elevations = c->elevations;
    o.cameraHeight = c->camera_height;
    o.layout = c->layout == EFFECTS_FOG_LAYOUT_WARPED ? effects::fog::TableOptions::Layout::kWarped
                                                      : effects::fog::TableOptions::Layout::kLinear;
    auto built = effects::fog::buildTable(f, o);
    if (!built.ok()) return fail(error, built.error());
    *table = new effects_fog_table{std::move(built.value())};
    return EFFECTS_OK;
  });
}

void effects_fog_table_free(effects_fog_table* t) { delete t; }
size_t effects_fog_table_width(const effects_fog_table* t) { return t ? t->table.width : 0; }
size_t effects_fog_table_height(const effects_fog_table* t) { return t ? t->table.height : 0; }
void effects_fog_table_range(const effects_fog_table* t, double* start, double* end) {
  if (start) *start = t ? t->table.rangeStart : 0;
  if (end) *end = t ? t->table.rangeEnd : 0;
}
double effects_fog_table_max_error(const effects_fog_table* t) { return t ? t->table.maxError : 0; }
const float* effects_fog_table_factor(const effects_fog_table* t) { return t ? t->table.factor.data() : nullptr; }
const float* effects_fog_table_inscatter(const effects_fog_table* t) {
  return t && !t->table.inscatter.empty() ? t->table.inscatter.data() : nullptr;
}
const float* effects_fog_table_transmittance(const effects_fog_table* t) {
  return t && !t->table.transmittanceRgb.empty() ? t->table.transmittanceRgb.data() : nullptr;
}
int effects_fog_table_axes(const effects_fog_table* t, double axes[7]) {
  if (!t || t->table.layout != effects::fog::TableOptions::Layout::kWarped || !axes) return 0;
  const auto& a = t->table.warped;
  const double v[7] = {a.rowK, a.falloff, a.kappa, a.lambda, a.factorStart, a.inscatterStart, a.end};
  std::memcpy(axes, v, sizeof v);
  return 1;
}

// ---- lightning ----------------------------------------------------------------------------------

void effects_bolt_params_defaults(effects_bolt_params* c) {
  if (!c) return;
  *c = effects_bolt_params{};
  try {
    fillBoltDefaults(c);
  } catch (...) {  // Params' default target could not be allocated: the size stays 0 (refused)
  }
}

}  // extern "C"

namespace {
void fillBoltDefaults(effects_bolt_params* c) {
  const effects::lightning::Params p;
  c->size = sizeof(effects_bolt_params);
  c->width = p.width, c->height = p.height, c->depth = 0;
  c->start[0] = p.start.x, c->start[1] = p.start.y;
  c->method = int32_t(EFFECTS_BOLT_FAST);
  c->eta = p.eta;
  c->seed = p.seed;
  c->max_steps = p.maxSteps;
  c->calibrated = 1;
  c->axis_growth = p.axisGrowth;
  c->lifetime = p.lifetime;
}
}  // namespace

extern "C" {

effects_status effects_bolt_grow(const effects_bolt_params* c, effects_bolt** bolt, effects_error** error) {
  namespace lt = effects::lightning;
  return guarded(error, [&] {
    if (bolt) *bolt = nullptr;
    if (!c || !bolt) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "params or bolt is NULL");
    if (!sized(c->size, sizeof(effects_bolt_params)))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/size", "must be sizeof(effects_bolt_params)");
    if (c->method < int32_t(EFFECTS_BOLT_FAST) || c->method > int32_t(EFFECTS_BOLT_CHARGES))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/method", "is not an effects_bolt_method");
    if (c->max_steps > lt::Limits{}.maxGrowthSteps)
      return fail(error, EFFECTS_LIMIT_EXCEEDED, "/maxSteps", "at most " + std::to_string(lt::Limits{}.maxGrowthSteps));
    if (c->target_count > lt::Limits{}.maxTargets)
      return fail(error, EFFECTS_LIMIT_EXCEEDED, "/targets", "at most " + std::to_string(lt::Limits{}.maxTargets) + " targets");
    if (c->target_count && !c->targets) return fail(error, EFFECTS_INVALID_ARGUMENT, "/targets", "is NULL");
    lt::Params p;
    p.width = c->width, p.height = c->height, p.depth = c->depth;
    p.start = {c->start[0], c->start[1], c->depth ? c->start[2] : 0};
    p.targets.clear();
    for (size_t i = 0; i < c->target_count; ++i)
      p.targets.push_back({c->targets[3 * i], c->targets[3 * i + 1], c->depth ? c->targets[3 * i + 2] : 0});
    p.method = lt::Method(int(c->method));
    p.eta = c->eta;
    p.neighbourhood = c->neighbourhood ? c->neighbourhood : lt::defaultNeighbourhood(c->depth);
    p.seed = c->seed;
    p.maxSteps = c->max_steps;
    // The grid's sides first: the flag arrays are read only once their size is known to be sane
    // (a region-only request stands in its start as the target here; grow() checks it all).
    lt::Params sides = p;
    if (sides.targets.empty() && c->target_region) sides.targets.push_back(sides.start);
    if (auto e = lt::validate(sides)) return fail(error, *e);
    if (auto e = lt::checkLimits(p, lt::Limits{})) return fail(error, *e);
    if (c->obstacles) p.obstacles.assign(c->obstacles, c->obstacles + cellsOf(p));
    if (c->target_region) p.targetRegion.assign(c->target_region, c->target_region + cellsOf(p));
    if (c->calibrated) {
      lt::calibrate(p);  // as the server does
    } else {
      p.axisGrowth = c->axis_growth;
      p.lifetime = c->lifetime;
    }
    auto grown = lt::grow(p);
    if (!grown.ok()) return fail(error, grown.error());
    auto* b = new effects_bolt{std::move(grown.value()), p.width, p.height, p.seed, {}, {}, {}, {}};
    for (const lt::Node& n : b->bolt.nodes) {
      b->cells.insert(b->cells.end(), {n.cell.x, n.cell.y, n.cell.z});
      b->parents.push_back(n.parent);
      b->steps.push_back(n.step);
    }
    b->main.assign(b->bolt.mainChannel.begin(), b->bolt.mainChannel.end());
    *bolt = b;
    return EFFECTS_OK;
  });
}

void effects_bolt_free(effects_bolt* b) { delete b; }
size_t effects_bolt_node_count(const effects_bolt* b) { return b ? b->bolt.nodes.size() : 0; }
const int32_t* effects_bolt_cells(const effects_bolt* b) { return b ? b->cells.data() : nullptr; }
const int32_t* effects_bolt_parents(const effects_bolt* b) { return b ? b->parents.data() : nullptr; }
const int32_t* effects_bolt_steps(const effects_bolt* b) { return b ? b->steps.data() : nullptr; }
size_t effects_bolt_main_channel(const effects_bolt* b, const int32_t** nodes) {
  if (nodes) *nodes = b ? b->main.data() : nullptr;
  return b ? b->main.size() : 0;
}
void effects_bolt_shape(const effects_bolt* b, double* cells, double* tips, double* branchPoints, double* dimension) {
  effects::lightning::BoltShape s;
  try {
    if (b) s = effects::lightning::shapeOf(b->bolt, b->width, b->height, b->bolt.depth);
  } catch (...) {  // out of memory for the box counts: zeros
    s = {};
  }
  if (cells) *cells = s.cells;
  if (tips) *tips = s.tips;
  if (branchPoints) *branchPoints = s.branchPoints;
  if (dimension) *dimension = s.dimension;
}

void effects_bolt_lines_params_defaults(effects_bolt_lines_params* c) {
  if (!c) return;
  const effects::lightning::ShapeParams s;
  *c = effects_bolt_lines_params{};
  c->size = sizeof(effects_bolt_lines_params);
  c->jitter = s.jitter;
  c->branch_width = s.branchWidth;
  c->branch_intensity = s.branchIntensity;
  c->branch_falloff = s.branchFalloff;
  c->time_scale = effects::lightning::TimelineParams{}.timeScale;
}

effects_status effects_bolt_lines_make(const effects_bolt* bolt, const effects_bolt_lines_params* c,
                                       effects_bolt_lines** out, effects_error** error) {
  namespace lt = effects::lightning;
  return guarded(error, [&] {
    if (out) *out = nullptr;
    if (!bolt || !c || !out) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "bolt, params or lines is NULL");
    if (!sized(c->size, sizeof(effects_bolt_lines_params)))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/size", "must be sizeof(effects_bolt_lines_params)");
    lt::ShapeParams s;
    s.jitter = c->jitter;
    s.jitterSeed = c->jitter_seed ? c->jitter_seed : bolt->seed;
    s.branchWidth = c->branch_width;
    s.branchIntensity = c->branch_intensity;
    s.branchFalloff = c->branch_falloff;
    if (!(s.jitter >= 0 && s.jitter <= 1))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/shape/jitter", "must be in [0, 1]");
    if (!(s.branchWidth > 0 && s.branchWidth <= 1e6) || !(s.branchIntensity >= 0 && s.branchIntensity <= 1) ||
        !(s.branchFalloff > 0 && s.branchFalloff <= 1e9))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/shape",
                  "branch width in (0, 1e6], intensity in [0, 1], falloff in (0, 1e9]");
    const std::vector<lt::Polyline> lines = lt::polylines(bolt->bolt, s);
    auto* made = new effects_bolt_lines;
    std::unique_ptr<effects_bolt_lines> owner(made);
    for (const lt::Polyline& l : lines) {
      effects_bolt_lines::Line line;
      line.main = l.main;
      line.width = l.width;
      for (const lt::Vertex& v : l.vertices) {
        line.points.insert(line.points.end(), {v.x, v.y, v.z});
        line.steps.push_back(v.step);
        line.intensities.push_back(v.intensity);
      }
      made->lines.push_back(std::move(line));
    }
    if (c->timeline) {
      lt::TimelineParams t;
      t.seed = c->timeline_seed ? c->timeline_seed : bolt->seed;
      t.timeScale = c->time_scale;
      auto made_tl = lt::timeline(bolt->bolt, lines, t);
      if (!made_tl.ok()) return fail(error, made_tl.error());
      lt::Timeline& tl = made_tl.value();
      for (size_t k = 0; k < made->lines.size(); ++k) {
        made->lines[k].leader = std::move(tl.leader[k]);
        made->lines[k].strokeDelay = std::move(tl.strokeDelay[k]);
      }
      made->connect = tl.connect;
      made->duration = tl.duration;
    }
    *out = owner.release();
    return EFFECTS_OK;
  });
}

void effects_bolt_lines_free(effects_bolt_lines* l) { delete l; }
size_t effects_bolt_lines_count(const effects_bolt_lines* l) { return l ? l->lines.size() : 0; }
static const effects_bolt_lines::Line* lineAt(const effects_bolt_lines* l, size_t k) {
  return l && k < l->lines.size() ? &l->lines[k] : nullptr;
}
int effects_bolt_line_is_main(const effects_bolt_lines* l, size_t k) { return lineAt(l, k) && lineAt(l, k)->main; }
float effects_bolt_line_width(const effects_bolt_lines* l, size_t k) {
  return lineAt(l, k) ? lineAt(l, k)->width : 0.0f;
}
size_t effects_bolt_line_vertex_count(const effects_bolt_lines* l, size_t k) {
  return lineAt(l, k) ? lineAt(l, k)->steps.size() : 0;
}
const float* effects_bolt_line_points(const effects_bolt_lines* l, size_t k) {
  return lineAt(l, k) ? lineAt(l, k)->points.data() : nullptr;
}
const int32_t* effects_bolt_line_steps(const effects_bolt_lines* l, size_t k) {
  return lineAt(l, k) ? lineAt(l, k)->steps.data() : nullptr;
}
const float* effects_bolt_line_intensities(const effects_bolt_lines* l, size_t k) {
  return lineAt(l, k) ? lineAt(l, k)->intensities.data() : nullptr;
}
const double* effects_bolt_line_leader(const effects_bolt_lines* l, size_t k) {
  return lineAt(l, k) && !lineAt(l, k)->leader.empty() ? lineAt(l, k)->leader.data() : nullptr;
}
const double* effects_bolt_line_stroke_delay(const effects_bolt_lines* l, size_t k) {
  return lineAt(l, k) && !lineAt(l, k)->strokeDelay.empty() ? lineAt(l, k)->strokeDelay.data() : nullptr;
}
void effects_bolt_lines_timing(const effects_bolt_lines* l, double* connect, double* duration) {
  if (connect) *connect = l ? l->connect : 0;
  if (duration) *duration = l ? l->duration : 0;
}

// ---- tangent frames ------------------------------------------------------------------------------

effects_status effects_tangents_generate(const effects_mesh_in* c, int32_t mode, effects_tangents** out,
                                         effects_error** error) {
  namespace tg = effects::tangents;
  return guarded(error, [&] {
    if (out) *out = nullptr;
    if (!c || !out) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "mesh or result is NULL");
    if (!sized(c->size, sizeof(effects_mesh_in)))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/size", "must be sizeof(effects_mesh_in)");
    if (mode < int32_t(EFFECTS_TANGENTS_MIKKTSPACE) || mode > int32_t(EFFECTS_TANGENTS_PER_VERTEX))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/mode", "is not an effects_tangent_mode");
    tg::Options o;
    if (c->vertex_count > o.maxVertices) return fail(error, EFFECTS_LIMIT_EXCEEDED, "/positions", "too many vertices");
    if (c->index_count > 3 * o.maxTriangles)
      return fail(error, EFFECTS_LIMIT_EXCEEDED, "/indices", "too many triangles");
    if ((c->vertex_count && (!c->positions || !c->uvs)) || (c->index_count && !c->indices))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/positions", "positions, uvs and indices must not be NULL");
    tg::Mesh m;
    m.positions.resize(c->vertex_count);
    m.uvs.resize(c->vertex_count);
    for (size_t i = 0; i < c->vertex_count; ++i) {
      m.positions[i] = {c->positions[3 * i], c->positions[3 * i + 1], c->positions[3 * i + 2]};
      m.uvs[i] = {c->uvs[2 * i], c->uvs[2 * i + 1]};
    }
    if (c->normals) {
      m.normals.resize(c->vertex_count);
      for (size_t i = 0; i < c->vertex_count; ++i)
        m.normals[i] = {c->normals[3 * i], c->normals[3 * i + 1], c->normals[3 * i + 2]};
    }
    m.indices.assign(c->indices, c->indices + c->index_count);
    o.mode = tg::Mode(int(mode));
    auto made = tg::generate(m, o);
    if (!made.ok()) return fail(error, made.error());
    auto* r = new effects_tangents{std::move(made.value()), {}, {}};
    for (const auto& t : r->out.tangents) r->frames.insert(r->frames.end(), {t.x, t.y, t.z, t.w});
    for (const auto& n : r->out.normals) r->normals.insert(r->normals.end(), {n.x, n.y, n.z});
    *out = r;
    return EFFECTS_OK;
  });
}

void effects_tangents_free(effects_tangents* r) { delete r; }
size_t effects_tangents_vertex_count(const effects_tangents* r) { return r ? r->out.tangents.size() : 0; }
const float* effects_tangents_frames(const effects_tangents* r) { return r ? r->frames.data() : nullptr; }
const float* effects_tangents_normals(const effects_tangents* r) { return r ? r->normals.data() : nullptr; }
const uint32_t* effects_tangents_remap(const effects_tangents* r) { return r ? r->out.remap.data() : nullptr; }
size_t effects_tangents_index_count(const effects_tangents* r) { return r ? r->out.indices.size() : 0; }
const uint32_t* effects_tangents_indices(const effects_tangents* r) { return r ? r->out.indices.data() : nullptr; }

// ---- soap bubble -----------------------------------------------------------------------------------

void effects_bubble_params_defaults(effects_bubble_params* c) {
  if (!c) return;
  const effects::bubble::Params p;
  const effects::bubble::MeshOptions o;
  *c = effects_bubble_params{};
  c->size = sizeof(effects_bubble_params);
  c->n1 = p.n1, c->n2 = p.n2, c->delta_speed = p.deltaSpeed, c->beta_speed = p.betaSpeed;
  c->rim_power = p.rimPower, c->mu_speed = p.muSpeed;
  c->paper_wobble = p.wobbleVariant == effects::bubble::WobbleVariant::kPaper;
  c->wobble_amplitude = p.wobbleAmplitude, c->wobble_frequency = p.wobbleFrequency;
  c->level = o.level;
  c->radius = o.radius;
  c->t = o.t;
  c->wobble = o.wobble;
}

effects_status effects_bubble_mesh_make(const effects_bubble_params* c, effects_bubble_mesh** out,
                                        effects_error** error) {
  return guarded(error, [&] {
    if (out) *out = nullptr;
    if (!out) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "mesh is NULL");
    effects::bubble::Params p;
    effects::bubble::MeshOptions o;
    if (effects_status s = toBubble(c, p, o, error)) return s;
    auto made = effects::bubble::icosphere(p, o);
    if (!made.ok()) return fail(error, made.error());
    *out = new effects_bubble_mesh{std::move(made.value())};
    return EFFECTS_OK;
  });
}

void effects_bubble_mesh_free(effects_bubble_mesh* m) { delete m; }
size_t effects_bubble_mesh_vertex_count(const effects_bubble_mesh* m) { return m ? m->mesh.positions.size() : 0; }
// glm's vectors are arrays of their components: a vector of them is the flat array C wants.
const float* effects_bubble_mesh_positions(const effects_bubble_mesh* m) {
  return m && !m->mesh.positions.empty() ? &m->mesh.positions[0].x : nullptr;
}
const float* effects_bubble_mesh_normals(const effects_bubble_mesh* m) {
  return m && !m->mesh.normals.empty() ? &m->mesh.normals[0].x : nullptr;
}
const float* effects_bubble_mesh_uvs(const effects_bubble_mesh* m) {
  return m && !m->mesh.uvs.empty() ? &m->mesh.uvs[0].x : nullptr;
}
const float* effects_bubble_mesh_tangents(const effects_bubble_mesh* m) {
  return m && !m->mesh.tangents.empty() ? &m->mesh.tangents[0].x : nullptr;
}
size_t effects_bubble_mesh_index_count(const effects_bubble_mesh* m) { return m ? m->mesh.indices.size() : 0; }
const uint32_t* effects_bubble_mesh_indices(const effects_bubble_mesh* m) {
  return m ? m->mesh.indices.data() : nullptr;
}

effects_status effects_bubble_uniforms(const effects_bubble_params* c, double t, double* top, double* bottom,
                                       double flow[2], effects_error** error) {
  return guarded(error, [&] {
    effects::bubble::Params p;
    effects::bubble::MeshOptions o;
    if (effects_status s = toBubble(c, p, o, error)) return s;
    if (!std::isfinite(t)) return fail(error, EFFECTS_INVALID_ARGUMENT, "/time", "must be finite");
    const effects::bubble::Film f = effects::bubble::film(p, t);
    const glm::dvec2 offset = effects::bubble::flowOffset(p, t);
    if (top) *top = f.top;
    if (bottom) *bottom = f.bottom;
    if (flow) flow[0] = offset.x, flow[1] = offset.y;
    return EFFECTS_OK;
  });
}

effects_status effects_bubble_shader(int core330, char** vertex, char** fragment, effects_error** error) {
  return guarded(error, [&] {
    if (vertex) *vertex = nullptr;
    if (fragment) *fragment = nullptr;
    if (!vertex || !fragment) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "vertex or fragment is NULL");
    effects::bubble::Features paper;
    paper.shading = effects::bubble::Shading::kPaper;  // the model effects_bubble_shader_uniforms_at feeds
    const auto src =
        effects::bubble::shader(paper, core330 ? effects::bubble::Glsl::kCore330 : effects::bubble::Glsl::kEs300);
    char* v = copyString(src.vertex);
    try {
      *fragment = copyString(src.fragment);
    } catch (...) {
      std::free(v);
      throw;
    }
    *vertex = v;
    return EFFECTS_OK;
  });
}

effects_status effects_bubble_shader_uniforms_at(const effects_bubble_params* c, double t,
                                                 effects_bubble_shader_uniforms* out, effects_error** error) {
  return guarded(error, [&] {
    namespace bb = effects::bubble;
    if (!out) return fail(error, EFFECTS_INVALID_ARGUMENT, "", "out is NULL");
    if (!sized(out->size, sizeof(effects_bubble_shader_uniforms)))
      return fail(error, EFFECTS_INVALID_ARGUMENT, "/size", "must be sizeof(effects_bubble_shader_uniforms)");
    bb::Params p;
    bb::MeshOptions o;
    if (effects_status s = toBubble(c, p, o, error)) return s;
    o.wobble = true;  // the shader wobbles the rest shape: the radius must keep its shape in float32
    if (auto e = bb::validate(p, o)) return fail(error, *e);
    if (!std::isfinite(t)) return fail(error, EFFECTS_INVALID_ARGUMENT, "/time", "must be finite");
    const bb::Film mu = bb::film(p, t);
    const bb::WobbleShape wobble = bb::wobbleInObject(p, o.radius);
    out->wobble_phase = bb::reducedPhase(p.deltaSpeed, t);
    out->wobble_amplitude = wobble.amplitude;
    out->wobble_frequency = wobble.frequency;
    out->film_top = mu.top;
    out->film_bottom = mu.bottom;
    out->eta = p.n1 / p.n2;
    out->flow_phase = bb::reducedPhase(p.betaSpeed, t);
    out->rim_power = p.rimPower;
    for (int i = 0; i < 4; ++i) out->base_color[i] = bb::kBaseColor[i];
    return EFFECTS_OK;
  });
}

}  // extern "C"
