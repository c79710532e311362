/* The C API (effects/effects.h) from C99: every family of functions on inputs with known
 * answers, the errors of hostile inputs (NULLs, NaN, huge grids, indices out of range, wrong
 * struct sizes, and the service's hostile corpus where its cases reach C) naming their
 * parameter, and no leaks (the ASan suite runs it). With --print it
 * prints one bolt and one fog table for tests/capi/ffi_test.sh to compare with C#.
 *   capi_test [--print] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <effects/effects.h>

static int failures = 0, checks = 0;
#define CHECK(cond, what)                                      \
  do {                                                         \
    ++checks;                                                  \
    if (!(cond)) {                                             \
      ++failures;                                              \
      fprintf(stderr, "FAIL %s (line %d)\n", what, __LINE__); \
    }                                                          \
  } while (0)

/* The call failed with this status and named this field; frees the error. (The error is read
 * through its address: C leaves the order of evaluating a call's arguments open.) */
static void expect_error(effects_status got, effects_error** ep, effects_status want, const char* field, const char* what) {
  effects_error* e = *ep;
  *ep = NULL;
  CHECK(got == want, what);
  CHECK(e != NULL && effects_error_status(e) == want, what);
  if (e && strcmp(effects_error_field(e), field) != 0) {
    fprintf(stderr, "  %s: field '%s' (%s), expected '%s'\n", what, effects_error_field(e), effects_error_message(e), field);
    CHECK(0, what);
  }
  effects_error_free(e);
}

static void print_reference(void) {
  effects_bolt_params p;
  effects_bolt* bolt = NULL;
  const int32_t target[3] = {24, 47, 0};
  effects_fog fog;
  effects_fog_table_options o;
  effects_fog_table* table = NULL;
  size_t i;
  effects_bolt_params_defaults(&p);
  p.width = p.height = 48;
  p.start[0] = 24, p.start[1] = 0;
  p.targets = target, p.target_count = 1;
  p.seed = 3;
  if (effects_bolt_grow(&p, &bolt, NULL) != EFFECTS_OK) exit(1);
  printf("bolt");
  for (i = 0; i < 3 * effects_bolt_node_count(bolt); ++i) printf(" %d", (int)effects_bolt_cells(bolt)[i]);
  printf("\n");
  effects_bolt_free(bolt);
  effects_fog_defaults(&fog);
  fog.type = EFFECTS_FOG_GL_EXP;
  fog.density = 0.05;
  effects_fog_table_options_defaults(&o);
  o.columns = 64, o.range_start = 0, o.range_end = 100;
  if (effects_fog_table_build(&fog, &o, &table, NULL) != EFFECTS_OK) exit(1);
  printf("fog");
  for (i = 0; i < effects_fog_table_width(table); ++i) printf(" %.9g", (double)effects_fog_table_factor(table)[i]);
  printf("\n");
  effects_fog_table_free(table);
}

static void test_fog(void) {
  effects_fog fog;
  effects_fog_table_options o;
  effects_fog_table* table = NULL;
  effects_error* e = NULL;
  double f = -1, axes[7];
  size_t i;
  effects_fog_defaults(&fog);
  CHECK(fog.size == sizeof fog, "defaults set the struct's size");
  fog.type = EFFECTS_FOG_GL_EXP;
  fog.density = 0.05;
  CHECK(effects_fog_factor(&fog, 0, 0, 20, &f, &e) == EFFECTS_OK && e == NULL, "fog factor");
  CHECK(fabs(f - exp(-1.0)) < 1e-12, "GL_EXP: f = exp(-density d)");
  effects_fog_table_options_defaults(&o);
  o.columns = 64, o.range_start = 0, o.range_end = 100;
  CHECK(effects_fog_table_build(&fog, &o, &table, &e) == EFFECTS_OK, "fog table");
  CHECK(effects_fog_table_width(table) == 64 && effects_fog_table_height(table) == 1, "table size");
  for (i = 0; i < 64; ++i) CHECK(fabs(effects_fog_table_factor(table)[i] - exp(-0.05 * 100.0 * (double)i / 63.0)) < 1e-6, "table entries");
  CHECK(effects_fog_table_inscatter(table) == NULL && effects_fog_table_axes(table, axes) == 0, "no glow, linear");
  effects_fog_table_free(table);

  fog.type = EFFECTS_FOG_HEIGHT;
  fog.height_falloff = 0.2;
  o.columns = 64, o.elevations = 0, o.layout = EFFECTS_FOG_LAYOUT_WARPED, o.camera_height = 2;
  CHECK(effects_fog_table_build(&fog, &o, &table, &e) == EFFECTS_OK, "warped height table");
  CHECK(effects_fog_table_height(table) == 32 && effects_fog_table_axes(table, axes) == 1 && axes[0] >= 1, "warped axes");
  effects_fog_table_free(table);

  fog.density = NAN;
  expect_error(effects_fog_factor(&fog, 0, 0, 1, &f, &e), &e, EFFECTS_INVALID_ARGUMENT, "/density", "NaN density");
  effects_fog_defaults(&fog);
  fog.type = 99;
  expect_error(effects_fog_validate(&fog, &e), &e, EFFECTS_INVALID_ARGUMENT, "/fogType", "unknown fog type");
  effects_fog_defaults(&fog);
  fog.size = 8;
  expect_error(effects_fog_validate(&fog, &e), &e, EFFECTS_INVALID_ARGUMENT, "/size", "a struct of the wrong size");
  effects_fog_defaults(&fog);
  fog.type = EFFECTS_FOG_GL_EXP;
  o.layout = EFFECTS_FOG_LAYOUT_LINEAR, o.columns = 1u << 30;
  CHECK(effects_fog_table_build(&fog, &o, &table, &e) != EFFECTS_OK && table == NULL, "a table past max_size");
  effects_error_free(e);
  expect_error(effects_fog_table_build(NULL, &o, &table, &e), &e, EFFECTS_INVALID_ARGUMENT, "", "NULL fog");
  /* Sizes whose product wraps around size_t: refused, not a short buffer written past. */
  fog.type = EFFECTS_FOG_HEIGHT;
  effects_fog_table_options_defaults(&o);
  o.columns = (size_t)1 << 32;
  expect_error(effects_fog_table_build(&fog, &o, &table, &e), &e, EFFECTS_LIMIT_EXCEEDED, "/size", "2^32 columns");
  o.columns = 2, o.elevations = (size_t)1 << 63;
  expect_error(effects_fog_table_build(&fog, &o, &table, &e), &e, EFFECTS_LIMIT_EXCEEDED, "/size", "2^63 elevations");
  o.elevations = 0, o.max_size = (size_t)-1;
  expect_error(effects_fog_table_build(&fog, &o, &table, &e), &e, EFFECTS_LIMIT_EXCEEDED, "/maxSize", "an unbounded max_size");
  effects_fog_table_options_defaults(&o);
  o.camera_height = NAN;
  expect_error(effects_fog_table_build(&fog, &o, &table, &e), &e, EFFECTS_INVALID_ARGUMENT, "/table", "a NaN camera height");

  /* The service's hostile corpus (proto/examples/invalid/g-fog-*, fog-*), as they reach C. */
  effects_fog_defaults(&fog);
  fog.type = EFFECTS_FOG_GL_EXP;
  fog.density = 1e308;
  CHECK(effects_fog_factor(&fog, 0, 0, 10, &f, &e) == EFFECTS_OK && f >= 0 && f <= 1, "density 1e308 (g-fog-density-1e308)");
  fog.density = -1;
  expect_error(effects_fog_validate(&fog, &e), &e, EFFECTS_INVALID_ARGUMENT, "/density", "negative density");
  effects_fog_defaults(&fog);
  fog.type = EFFECTS_FOG_HEIGHT;
  fog.height_falloff = -0.1;
  expect_error(effects_fog_validate(&fog, &e), &e, EFFECTS_INVALID_ARGUMENT, "/heightFalloff", "negative falloff (g-fog-height-falloff-negative)");
  effects_fog_defaults(&fog);
  fog.type = EFFECTS_FOG_DISTANCE_GAUSSIAN;
  fog.peak = 0;
  expect_error(effects_fog_validate(&fog, &e), &e, EFFECTS_INVALID_ARGUMENT, "/peak", "peak 0 (g-fog-peak-zero)");
  effects_fog_defaults(&fog);
  fog.type = EFFECTS_FOG_GL_LINEAR;
  fog.start = 5, fog.end = 5;
  CHECK(effects_fog_validate(&fog, &e) == EFFECTS_INVALID_ARGUMENT, "an empty GL_LINEAR range (fog-gl-linear-empty-range)");
  effects_error_free(e);
  e = NULL;
  effects_fog_defaults(&fog);
  fog.visibility_range = -3;
  CHECK(effects_fog_validate(&fog, &e) == EFFECTS_INVALID_ARGUMENT, "negative visibility (fog-negative-visibility)");
  effects_error_free(e);
}

static void test_bolt(void) {
  effects_bolt_params p;
  effects_bolt* bolt = NULL;
  effects_bolt_lines* lines = NULL;
  effects_bolt_lines_params lp;
  effects_error* e = NULL;
  const int32_t target[3] = {24, 47, 0}, outside[3] = {24, 48, 0};
  const int32_t* main_channel = NULL;
  uint8_t* ground;
  size_t n, k, main_lines = 0;
  double cells, tips, branches, dimension, connect, duration;

  effects_bolt_params_defaults(&p);
  p.width = p.height = 48;
  p.start[0] = 24, p.start[1] = 0;
  p.targets = target, p.target_count = 1;
  p.seed = 3;
  CHECK(effects_bolt_grow(&p, &bolt, &e) == EFFECTS_OK && e == NULL, "a bolt");
  n = effects_bolt_node_count(bolt);
  CHECK(n > 48 && effects_bolt_parents(bolt)[0] == -1, "a tree from the start");
  k = effects_bolt_main_channel(bolt, &main_channel);
  CHECK(k >= 48 && effects_bolt_cells(bolt)[3 * main_channel[k - 1] + 1] == 47, "the main channel ends on the target");
  effects_bolt_shape(bolt, &cells, &tips, &branches, &dimension);
  CHECK(cells == (double)n && tips >= 1 && dimension > 0.8 && dimension < 2, "shape");

  effects_bolt_lines_params_defaults(&lp);
  lp.timeline = 1;
  CHECK(effects_bolt_lines_make(bolt, &lp, &lines, &e) == EFFECTS_OK, "polylines and timeline");
  for (k = 0; k < effects_bolt_lines_count(lines); ++k) {
    main_lines += (size_t)effects_bolt_line_is_main(lines, k);
    CHECK(effects_bolt_line_vertex_count(lines, k) >= 2 && effects_bolt_line_leader(lines, k) != NULL, "a line with times");
  }
  CHECK(main_lines == 1 && effects_bolt_line_is_main(lines, 0), "one main channel, first");
  effects_bolt_lines_timing(lines, &connect, &duration);
  CHECK(connect > 0 && duration > connect, "the strike's timing");
  CHECK(effects_bolt_line_points(lines, 9999) == NULL, "a line past the end is NULL");
  effects_bolt_lines_free(lines);
  effects_bolt_free(bolt);

  /* The ground as a target region. */
  ground = calloc(48 * 48, 1);
  for (k = 0; k < 48; ++k) ground[47 * 48 + k] = 1;
  p.targets = NULL, p.target_count = 0, p.target_region = ground;
  CHECK(effects_bolt_grow(&p, &bolt, &e) == EFFECTS_OK, "a strike on the ground");
  k = effects_bolt_main_channel(bolt, &main_channel);
  CHECK(effects_bolt_cells(bolt)[3 * main_channel[k - 1] + 1] == 47, "struck the ground row");
  effects_bolt_free(bolt);
  free(ground);
  p.target_region = NULL;

  /* Hostile parameters. */
  p.targets = outside, p.target_count = 1;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/targets/0", "a target outside");
  CHECK(bolt == NULL, "no bolt on failure");
  p.targets = target;
  p.eta = NAN;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/eta", "NaN eta");
  p.eta = 2;
  p.width = p.height = 65536;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_LIMIT_EXCEEDED, "/grid", "2^32 cells");
  p.width = p.height = 1024, p.method = EFFECTS_BOLT_DBM;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_LIMIT_EXCEEDED, "/grid", "dbm on 1024^2 (O(cells) a step)");
  p.method = EFFECTS_BOLT_FAST, p.max_steps = (size_t)-1;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_LIMIT_EXCEEDED, "/maxSteps", "an unbounded step budget");
  effects_bolt_params_defaults(&p);
  p.targets = target, p.target_count = 1;
  p.width = -5;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/grid/width", "a negative width (HTTP's name)");
  p.width = 48, p.height = 1;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/grid/height", "height 1 (HTTP's name)");
  p.width = p.height = 48;
  p.targets = NULL;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/targets", "NULL targets with a count");
  p.target_count = 1000;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_LIMIT_EXCEEDED, "/targets", "too many targets");
  p.target_count = 0;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/targets", "no target at all");
  p.targets = target, p.target_count = 1, p.method = 7;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/method", "unknown method");
  p.method = EFFECTS_BOLT_CHARGES, p.depth = 16, p.width = p.height = 16;
  expect_error(effects_bolt_grow(&p, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "/method", "charges in 3-D");
  expect_error(effects_bolt_grow(NULL, &bolt, &e), &e, EFFECTS_INVALID_ARGUMENT, "", "NULL params");
  CHECK(effects_bolt_grow(NULL, &bolt, NULL) == EFFECTS_INVALID_ARGUMENT, "a NULL error pointer is allowed");
}

static void test_tangents(void) {
  const float positions[] = {0, 0, 0, 1, 0, 0, 1, 1, 0.2f, 0, 1, 0};
  const float uvs[] = {0, 0, 1, 0, 1, 1, 0, 1};
  const uint32_t indices[] = {0, 1, 2, 0, 2, 3}, bad[] = {0, 1, 2, 0, 2, 7};
  effects_mesh_in m = {sizeof(effects_mesh_in), positions, NULL, uvs, 4, indices, 6};
  effects_tangents* t = NULL;
  effects_error* e = NULL;
  size_t i;
  CHECK(effects_tangents_generate(&m, EFFECTS_TANGENTS_MIKKTSPACE, &t, &e) == EFFECTS_OK, "MikkTSpace");
  CHECK(effects_tangents_vertex_count(t) == 4 && effects_tangents_index_count(t) == 6, "no splits on a quad");
  for (i = 0; i < 4; ++i) {
    const float* f = effects_tangents_frames(t) + 4 * i;
    CHECK(fabs(f[0] - 1) < 0.05 && fabs(f[3]) == 1, "tangent along u, w = +-1");
  }
  effects_tangents_free(t);
  m.indices = bad;
  expect_error(effects_tangents_generate(&m, EFFECTS_TANGENTS_MIKKTSPACE, &t, &e), &e, EFFECTS_INVALID_ARGUMENT, "/indices/5",
               "an index past the vertices");
  m.indices = indices;
  m.uvs = NULL;
  expect_error(effects_tangents_generate(&m, EFFECTS_TANGENTS_MIKKTSPACE, &t, &e), &e, EFFECTS_INVALID_ARGUMENT, "/positions",
               "NULL uvs");
  m.uvs = uvs;
  m.size = 3;
  expect_error(effects_tangents_generate(&m, EFFECTS_TANGENTS_MIKKTSPACE, &t, &e), &e, EFFECTS_INVALID_ARGUMENT, "/size",
               "a struct of the wrong size");
}

static void test_bubble(void) {
  effects_bubble_params p;
  effects_bubble_mesh* m = NULL;
  effects_error* e = NULL;
  char *vertex = NULL, *fragment = NULL;
  double top = 0, bottom = 0, flow[2] = {0, 0};
  size_t i, n;
  effects_bubble_params_defaults(&p);
  p.level = 2;
  CHECK(effects_bubble_mesh_make(&p, &m, &e) == EFFECTS_OK, "an icosphere");
  n = effects_bubble_mesh_vertex_count(m);
  CHECK(n >= 162 && effects_bubble_mesh_index_count(m) == 3 * 20 * 16, "20 x 4^2 triangles");
  for (i = 0; i < n; ++i) {
    const float* q = effects_bubble_mesh_normals(m) + 3 * i;
    CHECK(fabs(sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) - 1) < 1e-4, "unit normals");
  }
  effects_bubble_mesh_free(m);
  CHECK(effects_bubble_uniforms(&p, 10, &top, &bottom, flow, &e) == EFFECTS_OK && top > 0 && bottom > 0, "film uniforms");
  CHECK(fabs(flow[0] * flow[0] + flow[1] * flow[1] - 1) < 1e-9, "flow offset (sin, cos)");
  CHECK(effects_bubble_shader(0, &vertex, &fragment, &e) == EFFECTS_OK, "shaders");
  CHECK(strstr(vertex, "#version 300 es") && strstr(fragment, "void main"), "GLSL ES text");
  /* The shader handed out is one the C API can feed: each uniform it declares is the client's
   * own or one effects_bubble_shader_uniforms_at gives. */
  {
    static const char* const fed[] = {"uModel", "uViewProjection", "uCameraPosition", "uEnvironment", "uFlowTexture",
                                      "uWobblePhase", "uWobbleAmplitude", "uWobbleFrequency", "uFilmTop", "uFilmBottom",
                                      "uEta", "uFlowPhase", "uRimPower", "uBaseColor"};
    const char* stages[2] = {vertex, fragment};
    int declared = 0, s2;
    for (s2 = 0; s2 < 2; ++s2) {
      const char* at = stages[s2];
      while ((at = strstr(at, "\nuniform ")) != NULL) {
        char type[32], name[64];
        size_t k, known = 0;
        CHECK(sscanf(at + 9, "%31s %63[A-Za-z0-9_]", type, name) == 2, "a uniform declaration");
        for (k = 0; k < sizeof fed / sizeof fed[0]; ++k) known |= strcmp(name, fed[k]) == 0;
        if (!known) fprintf(stderr, "uniform %s: nothing in the C API feeds it\n", name);
        CHECK(known, "every uniform of effects_bubble_shader is fed");
        ++declared, ++at;
      }
    }
    CHECK(declared >= 10, "the paper model's uniforms found");
  }
  {
    effects_bubble_shader_uniforms u;
    memset(&u, 0, sizeof u);
    u.size = sizeof u;
    CHECK(effects_bubble_shader_uniforms_at(&p, 1e9, &u, &e) == EFFECTS_OK, "the shader's uniforms at t = 1e9");
    CHECK(u.wobble_phase >= 0 && u.wobble_phase < 6.283185307179587 && u.flow_phase >= 0 && u.flow_phase < 6.283185307179587,
          "phases reduced to [0, 2 pi)");
    CHECK(fabs(u.eta - p.n1 / p.n2) < 1e-15 && u.rim_power == p.rim_power && u.base_color[3] == 1, "eta, rim, base colour");
    u.size = 8;
    expect_error(effects_bubble_shader_uniforms_at(&p, 0, &u, &e), &e, EFFECTS_INVALID_ARGUMENT, "/size", "a wrong size");
    u.size = sizeof u;
    expect_error(effects_bubble_shader_uniforms_at(&p, INFINITY, &u, &e), &e, EFFECTS_INVALID_ARGUMENT, "/time", "time inf");
    p.radius = 0;
    expect_error(effects_bubble_shader_uniforms_at(&p, 0, &u, &e), &e, EFFECTS_INVALID_ARGUMENT, "/radius", "uniforms for radius 0");
    p.radius = NAN;
    expect_error(effects_bubble_shader_uniforms_at(&p, 0, &u, &e), &e, EFFECTS_INVALID_ARGUMENT, "/radius", "uniforms for radius NaN");
    effects_bubble_params_defaults(&p);
  }
  effects_string_free(vertex);
  effects_string_free(fragment);
  p.level = 40;
  CHECK(effects_bubble_mesh_make(&p, &m, &e) != EFFECTS_OK && m == NULL, "level 40 is refused");
  effects_error_free(e);
  p.level = 2;
  p.n2 = NAN;
  expect_error(effects_bubble_mesh_make(&p, &m, &e), &e, EFFECTS_INVALID_ARGUMENT, "/n2", "NaN index of refraction");

  /* The service's hostile corpus (proto/examples/invalid/g-bubble-*), as they reach C. */
  effects_bubble_params_defaults(&p);
  p.radius = 0;
  expect_error(effects_bubble_mesh_make(&p, &m, &e), &e, EFFECTS_INVALID_ARGUMENT, "/radius", "radius 0 (g-bubble-radius-zero)");
  p.radius = -0.0;
  expect_error(effects_bubble_mesh_make(&p, &m, &e), &e, EFFECTS_INVALID_ARGUMENT, "/radius", "radius -0 (g-bubble-radius-negative-zero)");
  effects_bubble_params_defaults(&p);
  p.n1 = 1e300;
  expect_error(effects_bubble_mesh_make(&p, &m, &e), &e, EFFECTS_INVALID_ARGUMENT, "/n1", "n1 1e300 (g-bubble-n1-huge)");
  effects_bubble_params_defaults(&p);
  p.level = -1;
  CHECK(effects_bubble_mesh_make(&p, &m, &e) != EFFECTS_OK && m == NULL, "level -1 (g-bubble-level-negative)");
  effects_error_free(e);
  e = NULL;
  effects_bubble_params_defaults(&p);
  CHECK(effects_bubble_uniforms(&p, 1e308, &top, &bottom, flow, &e) == EFFECTS_OK, "time 1e308 (g-bubble-time-1e308)");
  CHECK(isfinite(top) && isfinite(bottom) && isfinite(flow[0]) && isfinite(flow[1]), "finite film at time 1e308");
}

int main(int argc, char** argv) {
  if (argc > 1 && strcmp(argv[1], "--print") == 0) {
    print_reference();
    return 0;
  }
  CHECK(effects_c_api_version() == EFFECTS_C_API_VERSION && strchr(effects_version(), '.'), "versions");
  test_fog();
  test_bolt();
  test_tangents();
  test_bubble();
  printf("%d checks, %d failed\n", checks, failures);
  return failures ? 1 : 0;
}
