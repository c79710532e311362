// libFuzzer: the C API's bolt entry point (effects_bolt_grow, then polylines with a timeline) on
// parameters and obstacle and region bitmaps taken from the input. Whatever it answers must be
// a tree inside the grid, or an error naming a field; nothing may crash, leak or hang.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <effects/effects.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 16) return 0;
  effects_bolt_params p;
  effects_bolt_params_defaults(&p);
  // Grids up to 24 x 24, or 10 x 10 x 6 in 3-D: the exact methods' cost grows with the square
  // of the cells (a field solve each step), and one input must stay well under the 10 s timeout
  // under ASan (there a 32 x 32 x 4 DBM took over 10 s, 12 x 12 x 8 3 s, 32 x 32 5 s).
  p.depth = data[2] % 4 == 0 ? 3 + data[3] % 4 : 0;
  p.width = 3 + data[0] % (p.depth ? 8 : 22), p.height = 3 + data[1] % (p.depth ? 8 : 22);
  const int32_t depth = p.depth ? p.depth : 1;
  p.start[0] = data[4] % (p.width + 1), p.start[1] = data[5] % (p.height + 1), p.start[2] = data[6] % (depth + 1);
  int32_t target[3] = {data[7] % (p.width + 1), data[8] % (p.height + 1), data[9] % (depth + 1)};
  p.targets = target;
  p.target_count = data[10] % 3 == 0 ? 0 : 1;
  p.method = effects_bolt_method(data[11] % 4);  // 3 is no method
  p.eta = double(data[12]) / 16.0;
  p.seed = data[13];
  p.max_steps = 20000;
  const size_t cells = size_t(p.width) * size_t(p.height) * size_t(depth);
  std::vector<uint8_t> obstacles(cells, 0), region(cells, 0);
  for (size_t i = 0; i < cells; ++i) {
    const size_t bit = 16 * 8 + 2 * i;  // two bits per cell after the header: obstacle, region
    if (bit / 8 >= size) break;
    obstacles[i] = (data[bit / 8] >> (bit % 8)) & 1;
    region[i] = (data[bit / 8] >> (bit % 8 + 1)) & 1;
  }
  if (data[14] & 1) p.obstacles = obstacles.data();
  if (data[14] & 2) p.target_region = region.data();
  effects_bolt* bolt = nullptr;
  effects_error* error = nullptr;
  if (const effects_status s = effects_bolt_grow(&p, &bolt, &error); s != EFFECTS_OK) {
    if (bolt || (!error && s != EFFECTS_OUT_OF_MEMORY) || (error && effects_error_message(error)[0] == 0)) std::abort();
    effects_error_free(error);
    return 0;
  }
  const size_t n = effects_bolt_node_count(bolt);
  const int32_t* c = effects_bolt_cells(bolt);
  const int32_t* parents = effects_bolt_parents(bolt);
  for (size_t i = 0; i < n; ++i) {
    if (c[3 * i] < 0 || c[3 * i] >= p.width || c[3 * i + 1] < 0 || c[3 * i + 1] >= p.height || c[3 * i + 2] < 0 ||
        c[3 * i + 2] >= depth)
      std::abort();
    if ((i == 0) != (parents[i] < 0) || parents[i] >= int32_t(i)) std::abort();
  }
  effects_bolt_lines_params lp;
  effects_bolt_lines_params_defaults(&lp);
  lp.timeline = data[15] & 1;
  effects_bolt_lines* lines = nullptr;
  if (effects_bolt_lines_make(bolt, &lp, &lines, nullptr) != EFFECTS_OK) std::abort();
  effects_bolt_lines_free(lines);
  effects_bolt_free(bolt);
  return 0;
}
