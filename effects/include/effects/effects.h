/* effects/effects.h — the effect library's C API (C99; no C++ type crosses it).
 *
 * For engines and languages that cannot use the C++ headers: C, C# (P/Invoke), Rust, Godot
 * GDNative. Link libeffects (static: also the C++ runtime and -pthread; shared:
 * libeffects.so.<major>). The C++ API (effects/fog.h, lightning.h, tangents.h, bubble.h)
 * holds the documentation of every parameter; this header names the C spelling and the rules
 * of the boundary. docs/engines.md shows it from C and C#.
 *
 * Rules that hold for every function:
 *   - Results are opaque handles the caller frees with the matching *_free (NULL is ignored),
 *     or strings freed with effects_string_free. Pointers an accessor returns (arrays,
 *     strings) live as long as their handle and must not be freed.
 *   - Functions that can fail return an effects_status and, when `error` is not NULL, set
 *     *error to a new effects_error (free it with effects_error_free) on failure and to NULL on
 *     success. The error names the offending parameter as a JSON pointer
 *     ("/targets/0", "/grid", "/indices/5"), the same the HTTP API names.
 *   - Untrusted input is safe: every parameter is validated as the service validates a
 *     request (ranges, sizes, indices, NaN) before any work; counts that would not fit
 *     memory give EFFECTS_LIMIT_EXCEEDED or EFFECTS_OUT_OF_MEMORY, never a crash. Arrays must
 *     hold the number of elements their count says (the library cannot check a pointer).
 *   - Thread-safety: every function is reentrant; distinct handles may be used from distinct
 *     threads at once; a handle is read-only after it is made and may be read from several
 *     threads.
 *   - Determinism: the same parameters give the same result, bit for bit, as the server.
 *   - Structs with a `size` member: set it to sizeof(the struct) (the *_defaults functions
 *     do), so that a later library with a longer struct can tell an older caller's.
 *   - Enumerations cross as int32_t (a field or parameter names its enum): any value is safe,
 *     one outside the enum is EFFECTS_INVALID_ARGUMENT.
 *   - Work is bounded: grids, tables and meshes have the service's default limits (below),
 *     and a request over one is EFFECTS_LIMIT_EXCEEDED before any work.
 *   - When even the error cannot be allocated, the status is EFFECTS_OUT_OF_MEMORY and *error
 *     is NULL.
 */
#ifndef EFFECTS_EFFECTS_H
#define EFFECTS_EFFECTS_H

#include <stddef.h>
#include <stdint.h>

#include "effects/export.h"

#ifdef __cplusplus
extern "C" {
#endif
EFFECTS_API_BEGIN

#define EFFECTS_C_API_VERSION 2 /* 2: effects_bubble_shader_uniforms_at; the shader is seed 000's */

/* ---- errors, versions, strings ------------------------------------------------------------ */

typedef enum effects_status {
  EFFECTS_OK = 0,
  EFFECTS_INVALID_ARGUMENT = 1, /* a parameter breaks its documented rule (HTTP 400) */
  EFFECTS_UNSATISFIABLE = 2,    /* well-formed, but cannot be served: an unreachable target (422) */
  EFFECTS_LIMIT_EXCEEDED = 3,   /* over a size or step bound (413) */
  EFFECTS_OUT_OF_MEMORY = 4,
  EFFECTS_INTERNAL = 5 /* a bug: please report it with the parameters */
} effects_status;

typedef struct effects_error effects_error;
effects_status effects_error_status(const effects_error* error);
/* The parameter as a JSON pointer ("" for the call as a whole), and the rule it broke. */
const char* effects_error_field(const effects_error* error);
const char* effects_error_message(const effects_error* error);
void effects_error_free(effects_error* error);

/* The library's version, "major.minor.patch"; EFFECTS_C_API_VERSION of the library. */
const char* effects_version(void);
int effects_c_api_version(void);
void effects_string_free(char* s);

/* ---- fog (effects/fog.h) ------------------------------------------------------------------- */

typedef enum effects_fog_type {
  EFFECTS_FOG_X3D_LINEAR = 0,   /* "LINEAR" */
  EFFECTS_FOG_X3D_EXPONENTIAL,  /* "EXPONENTIAL" */
  EFFECTS_FOG_GL_LINEAR,
  EFFECTS_FOG_GL_EXP,
  EFFECTS_FOG_GL_EXP2,
  EFFECTS_FOG_DISTANCE_EXP2,
  EFFECTS_FOG_DISTANCE_GAUSSIAN,
  EFFECTS_FOG_HEIGHT,
  EFFECTS_FOG_ATMOSPHERIC
} effects_fog_type;

typedef enum effects_fog_convention { EFFECTS_FOG_EFFECTD = 0, EFFECTS_FOG_FILAMENT, EFFECTS_FOG_UNREAL } effects_fog_convention;

/* effects::fog::Fog. has_second_layer and has_directional switch the optional parts on;
 * directional_exponent <= 0 means the Henyey-Greenstein lobe (g). cutoff_distance <= 0 means
 * none (infinity). */
typedef struct effects_fog {
  size_t size;
  int32_t type;       /* an effects_fog_type */
  int32_t convention; /* an effects_fog_convention */
  double color[3];
  double visibility_range, start, end, density, distance_coefficient, peak, height_falloff, base_height;
  double extinction[3], inscattering[3];
  double start_distance, max_opacity, cutoff_distance;
  int has_second_layer;
  double second_density, second_height_falloff, second_base_height;
  int has_directional;
  double directional_color[3], directional_direction[3], directional_g, directional_exponent,
      directional_start_distance;
} effects_fog;

/* Fills *fog with the library's defaults (and fog->size). */
void effects_fog_defaults(effects_fog* fog);
/* Checks *fog as /v1/fog checks its "fog" (effects::fog::validate). Statuses: EFFECTS_OK;
 * EFFECTS_INVALID_ARGUMENT: "" for a NULL fog, "/size", "/fogType" or "/convention" for a
 * wrong size or enum, otherwise the field fog.json names ("/density", "/color/1", ...) with
 * its range in the message. */
effects_status effects_fog_validate(const effects_fog* fog, effects_error** error);
/* f (the object's weight, 1 = no fog) along a ray from height origin_y with unit direction y
 * component dir_y, at distance. Sets *f; fails only where effects_fog_validate does. */
effects_status effects_fog_factor(const effects_fog* fog, double origin_y, double dir_y, double distance, double* f,
                                  effects_error** error);

typedef enum effects_fog_layout { EFFECTS_FOG_LAYOUT_LINEAR = 0, EFFECTS_FOG_LAYOUT_WARPED } effects_fog_layout;
/* effects::fog::TableOptions: columns (distance samples) 0 picks the smallest number meeting
 * max_error; range_end <= range_start (both 0 by default) means the default range [0, where f
 * completes]; elevations 0: HEIGHT's default rows; columns x elevations at most max_size (by
 * default 65536, the service's default; at most 2^24, the contract's largest table). */
typedef struct effects_fog_table_options {
  size_t size;
  size_t columns;
  double max_error;
  size_t max_size;
  double range_start, range_end;
  size_t elevations;
  double camera_height;
  int32_t layout; /* an effects_fog_layout */
} effects_fog_table_options;
void effects_fog_table_options_defaults(effects_fog_table_options* options);

typedef struct effects_fog_table effects_fog_table;
/* The fog's lookup table (effects::fog::table), as /v1/fog's "table" builds it. Sets *table
 * (free it with effects_fog_table_free) or NULL on failure. Statuses: EFFECTS_OK; every status
 * of effects_fog_validate; EFFECTS_INVALID_ARGUMENT: "" for NULL fog, options or table,
 * "/size" or "/layout" for a wrong size or enum, "/table" for an option outside its range
 * (max_error in [0, 1], elevations, camera_height finite); EFFECTS_LIMIT_EXCEEDED: "/maxSize"
 * above 2^24, "/size" when columns x elevations exceeds max_size or no size up to it meets
 * max_error. */
effects_status effects_fog_table_build(const effects_fog* fog, const effects_fog_table_options* options,
                                       effects_fog_table** table, effects_error** error);
void effects_fog_table_free(effects_fog_table* table);
size_t effects_fog_table_width(const effects_fog_table* table);  /* distance samples */
size_t effects_fog_table_height(const effects_fog_table* table); /* elevations (1 but for HEIGHT) */
void effects_fog_table_range(const effects_fog_table* table, double* start, double* end);
double effects_fog_table_max_error(const effects_fog_table* table);
/* width * height f values, row-major; inscatter (1 - f_dir; NULL without a directional part);
 * transmittance (3 per entry; NULL but for ATMOSPHERIC). */
const float* effects_fog_table_factor(const effects_fog_table* table);
const float* effects_fog_table_inscatter(const effects_fog_table* table);
const float* effects_fog_table_transmittance(const effects_fog_table* table);
/* A warped table's axes (docs/using/fog.md section 4): k, falloff, kappa, lambda, factorStart,
 * inscatterStart, end, in that order; returns 0 (and fills nothing) for a linear table. */
int effects_fog_table_axes(const effects_fog_table* table, double axes[7]);

/* ---- lightning (effects/lightning.h) ------------------------------------------------------- */

typedef enum effects_bolt_method { EFFECTS_BOLT_FAST = 0, EFFECTS_BOLT_DBM, EFFECTS_BOLT_CHARGES } effects_bolt_method;

/* effects::lightning::Params, with the server's calibration applied when `calibrated` is 1
 * (the default; 0 takes axis_growth and lifetime as given). depth 0: a 2-D grid. Cells are
 * int32 triples x, y, z (z 0 in 2-D). obstacles and target_region: NULL, or one byte per cell
 * (x fastest, then y, then z; nonzero = in the set). Limits (effects::lightning::Limits, the
 * service's defaults): fast
 * grids up to 2^24 cells, dbm and charges (every step costs O(cells)) up to 256^2 cells in 2-D
 * and 64^3 in 3-D, max_steps up to 2 000 000, 64 targets. */
typedef struct effects_bolt_params {
  size_t size;
  int32_t width, height, depth;
  int32_t start[3];
  const int32_t* targets; /* 3 per target */
  size_t target_count;
  const uint8_t* obstacles;
  const uint8_t* target_region;
  int32_t method; /* an effects_bolt_method */
  double eta;
  int32_t neighbourhood; /* 0: 8 in 2-D, 26 in 3-D */
  uint64_t seed;
  size_t max_steps;
  int calibrated;
  double axis_growth;
  int32_t lifetime;
} effects_bolt_params;
void effects_bolt_params_defaults(effects_bolt_params* params);

typedef struct effects_bolt effects_bolt;
/* Grows a bolt (effects::lightning::grow) as /v1/lightning does. Sets *bolt (free it with
 * effects_bolt_free) or NULL on failure. Statuses: EFFECTS_OK; EFFECTS_INVALID_ARGUMENT: "" for
 * NULL params or bolt, "/size", "/method" for a wrong size or enum, "/grid/width" or
 * "/grid/height" below 3, "/grid/depth", "/start", "/targets" (NULL with a count),
 * "/targets/<i>" (outside the grid), "/eta" ([0, 50]), "/neighbourhood" and the other fields
 * effects::lightning::validate names; EFFECTS_LIMIT_EXCEEDED: "/grid/width" or "/grid/height"
 * over 65 536 (4 096 in 3-D), "/grid" over the cell limits above, "/maxSteps", "/targets"
 * (more than 64); EFFECTS_UNSATISFIABLE naming a target in an obstacle, on the start, or that
 * no path reaches. */
effects_status effects_bolt_grow(const effects_bolt_params* params, effects_bolt** bolt, effects_error** error);
void effects_bolt_free(effects_bolt* bolt);
/* Cells in growth order: node i at cells[3i..3i+2], grown from parents[i] (-1 for the start) at
 * steps[i]. The main channel: node indices from the start to the last target. */
size_t effects_bolt_node_count(const effects_bolt* bolt);
const int32_t* effects_bolt_cells(const effects_bolt* bolt);
const int32_t* effects_bolt_parents(const effects_bolt* bolt);
const int32_t* effects_bolt_steps(const effects_bolt* bolt);
size_t effects_bolt_main_channel(const effects_bolt* bolt, const int32_t** nodes);
/* The bolt's shape: cells, tips, branch points and the box-counting dimension. */
void effects_bolt_shape(const effects_bolt* bolt, double* cells, double* tips, double* branch_points, double* dimension);

/* Polylines for a renderer (effects::lightning::ShapeParams; jitter_seed 0 = the bolt's seed)
 * and, when timeline is not NULL, the strike's timeline (TimelineParams' defaults, seed =
 * timeline_seed or the bolt's seed when 0). */
typedef struct effects_bolt_lines_params {
  size_t size;
  double jitter;
  uint64_t jitter_seed;
  double branch_width, branch_intensity, branch_falloff;
  int timeline;
  uint64_t timeline_seed;
  double time_scale;
} effects_bolt_lines_params;
void effects_bolt_lines_params_defaults(effects_bolt_lines_params* params);

typedef struct effects_bolt_lines effects_bolt_lines;
/* Sets *lines (free with effects_bolt_lines_free) or NULL on failure. Statuses: EFFECTS_OK;
 * EFFECTS_INVALID_ARGUMENT: "" for NULL arguments, "/size", "/shape/jitter" ([0, 1]), "/shape"
 * (the branch fields), and with a timeline "/timeScale" ((0, 1e6]). */
effects_status effects_bolt_lines_make(const effects_bolt* bolt, const effects_bolt_lines_params* params,
                                       effects_bolt_lines** lines, effects_error** error);
void effects_bolt_lines_free(effects_bolt_lines* lines);
size_t effects_bolt_lines_count(const effects_bolt_lines* lines);
/* Line k: main channel (1) or branch (0), its width in cells, its vertices (x, y, z floats in
 * grid units, 3 per vertex) with each vertex's step and intensity; with a timeline each
 * vertex's leader time and stroke delay (seconds; NULL without). */
int effects_bolt_line_is_main(const effects_bolt_lines* lines, size_t k);
float effects_bolt_line_width(const effects_bolt_lines* lines, size_t k);
size_t effects_bolt_line_vertex_count(const effects_bolt_lines* lines, size_t k);
const float* effects_bolt_line_points(const effects_bolt_lines* lines, size_t k);
const int32_t* effects_bolt_line_steps(const effects_bolt_lines* lines, size_t k);
const float* effects_bolt_line_intensities(const effects_bolt_lines* lines, size_t k);
const double* effects_bolt_line_leader(const effects_bolt_lines* lines, size_t k);
const double* effects_bolt_line_stroke_delay(const effects_bolt_lines* lines, size_t k);
/* The timeline's connect time and duration (0 without a timeline). */
void effects_bolt_lines_timing(const effects_bolt_lines* lines, double* connect, double* duration);

/* ---- tangent frames (effects/tangents.h) ---------------------------------------------------- */

typedef enum effects_tangent_mode { EFFECTS_TANGENTS_MIKKTSPACE = 0, EFFECTS_TANGENTS_PER_TRIANGLE, EFFECTS_TANGENTS_PER_VERTEX } effects_tangent_mode;

/* positions and (optional, NULL) normals: 3 floats per vertex; uvs: 2 per vertex; indices: 3
 * per triangle, counter-clockwise = front. */
typedef struct effects_mesh_in {
  size_t size;
  const float* positions;
  const float* normals;
  const float* uvs;
  size_t vertex_count;
  const uint32_t* indices;
  size_t index_count;
} effects_mesh_in;

typedef struct effects_tangents effects_tangents;
/* mode: an effects_tangent_mode. Up to 2 000 000 vertices and 4 000 000 triangles. Sets
 * *result (free with effects_tangents_free) or NULL on failure. Statuses: EFFECTS_OK;
 * EFFECTS_INVALID_ARGUMENT: "" for NULL arguments, "/size", "/mode", "/positions" (missing, or
 * not finite), "/uvs", "/indices/<i>" (past vertex_count, or a count not a multiple of 3);
 * EFFECTS_LIMIT_EXCEEDED: "/positions", "/indices" over the counts above. */
effects_status effects_tangents_generate(const effects_mesh_in* mesh, int32_t mode, effects_tangents** result,
                                         effects_error** error);
void effects_tangents_free(effects_tangents* result);
/* Output vertices (the first vertex_count are the input's; split copies follow): tangents
 * (x, y, z, w; bitangent = w cross(N, T)), normals (3 per vertex), remap (the input vertex each
 * copies), indices (3 per triangle over output vertices). */
size_t effects_tangents_vertex_count(const effects_tangents* result);
const float* effects_tangents_frames(const effects_tangents* result);
const float* effects_tangents_normals(const effects_tangents* result);
const uint32_t* effects_tangents_remap(const effects_tangents* result);
size_t effects_tangents_index_count(const effects_tangents* result);
const uint32_t* effects_tangents_indices(const effects_tangents* result);

/* ---- soap bubble (effects/bubble.h) -------------------------------------------------------- */

/* effects::bubble::Params and MeshOptions. */
typedef struct effects_bubble_params {
  size_t size;
  double n1, n2, delta_speed, beta_speed, rim_power, mu_speed;
  int paper_wobble; /* 0: relative wobble (default), 1: the paper's */
  double wobble_amplitude, wobble_frequency;
  int level;
  double radius, t;
  int wobble;
} effects_bubble_params;
void effects_bubble_params_defaults(effects_bubble_params* params);

typedef struct effects_bubble_mesh effects_bubble_mesh;
/* The icosphere (effects::bubble::icosphere) as /v1/bubble's "mesh". Sets *mesh (free with
 * effects_bubble_mesh_free) or NULL on failure. Statuses: EFFECTS_OK; EFFECTS_INVALID_ARGUMENT:
 * "" for NULL arguments, "/size", "/time" (not finite), "/n1", "/n2", "/radius" and the other
 * fields effects::bubble::validate names, "/radius" outside [1e-6, 1e6]; EFFECTS_LIMIT_EXCEEDED:
 * "/level" outside [0, its maximum]; EFFECTS_UNSATISFIABLE: "/radius" too small for the paper's
 * wobble in float32 (wobble on). */
effects_status effects_bubble_mesh_make(const effects_bubble_params* params, effects_bubble_mesh** mesh,
                                        effects_error** error);
void effects_bubble_mesh_free(effects_bubble_mesh* mesh);
/* Positions and normals 3 floats, uvs 2, tangents 4 (MikkTSpace) per vertex; indices 3 per
 * triangle, counter-clockwise. */
size_t effects_bubble_mesh_vertex_count(const effects_bubble_mesh* mesh);
const float* effects_bubble_mesh_positions(const effects_bubble_mesh* mesh);
const float* effects_bubble_mesh_normals(const effects_bubble_mesh* mesh);
const float* effects_bubble_mesh_uvs(const effects_bubble_mesh* mesh);
const float* effects_bubble_mesh_tangents(const effects_bubble_mesh* mesh);
size_t effects_bubble_mesh_index_count(const effects_bubble_mesh* mesh);
const uint32_t* effects_bubble_mesh_indices(const effects_bubble_mesh* mesh);

/* The film's uniforms at time t (seed 000 eqns 3 and 9, docs/effects.md section 3): the film's
 * top and bottom thickness factors and the texture flow's offset. */
effects_status effects_bubble_uniforms(const effects_bubble_params* params, double t, double* film_top,
                                       double* film_bottom, double flow_offset[2], effects_error** error);

/* The shaders of seed 000's model (the paper's: reflection, refraction, rim, texture flow and
 * wobble; /v1/bubble's shading "paper" with its default features), GLSL ES 3.00 when core330 is
 * 0, else 3.30 core: vertex and fragment text, each freed with effects_string_free. Attributes
 * aPosition, aNormal, aUv at locations 0, 1, 2 (effects_bubble_mesh_*). Its uniforms are the
 * client's own (uModel, uViewProjection, uCameraPosition, uEnvironment: the sky as a cube map,
 * uFlowTexture: the flow texture, repeating) and those effects_bubble_shader_uniforms_at
 * gives. Statuses: EFFECTS_OK; EFFECTS_INVALID_ARGUMENT ("") when vertex or fragment is NULL. */
effects_status effects_bubble_shader(int core330, char** vertex, char** fragment, effects_error** error);

/* The values effects_bubble_shader's uniforms take at time t, named as the shader names them
 * (the values /v1/bubble answers with shading "paper"); phases are reduced modulo 2 pi in
 * extended precision, so t = 1e9 s keeps its digits. The wobble is in object units for a mesh
 * of params->radius. */
typedef struct effects_bubble_shader_uniforms {
  size_t size;                 /* sizeof(effects_bubble_shader_uniforms), set by the caller */
  double wobble_phase;         /* uWobblePhase: delta_speed t mod 2 pi (eqn 11) */
  double wobble_amplitude;     /* uWobbleAmplitude */
  double wobble_frequency;     /* uWobbleFrequency, radians per object unit */
  double film_top, film_bottom; /* uFilmTop, uFilmBottom (eqn 3) */
  double eta;                  /* uEta: n1 / n2 (eqn 5) */
  double flow_phase;           /* uFlowPhase: beta_speed t mod 2 pi (eqn 9) */
  double rim_power;            /* uRimPower (eqn 10) */
  double base_color[4];        /* uBaseColor: colour and alpha without any feature */
} effects_bubble_shader_uniforms;
/* Statuses: EFFECTS_OK; those of effects_bubble_mesh_make for params (the radius checked as for
 * a wobbled mesh: the shader wobbles); EFFECTS_INVALID_ARGUMENT: "/time" when t is not finite,
 * "/size" when out->size is not sizeof(effects_bubble_shader_uniforms), "" when out is NULL. */
effects_status effects_bubble_shader_uniforms_at(const effects_bubble_params* params, double t,
                                                 effects_bubble_shader_uniforms* out, effects_error** error);

EFFECTS_API_END
#ifdef __cplusplus
}
#endif

#endif /* EFFECTS_EFFECTS_H */
