// Sheets of bolts (sheets.h), drawn with gnuplot (Debian's gnuplot-nox).
#include "sheets.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>

namespace report {

namespace fs = std::filesystem;
namespace lt = effects::lightning;

void addPanel(Sheet& sheet, const lt::Bolt& bolt, const std::string& title) {
  std::vector<char> onMain(bolt.nodes.size(), 0);
  for (int n : bolt.mainChannel) onMain[size_t(n)] = 1;
  std::vector<std::array<float, 4>> branches, main;
  for (size_t i = 0; i < bolt.nodes.size(); ++i) {
    const lt::Node& n = bolt.nodes[i];
    if (n.parent < 0) continue;
    const lt::Cell a = bolt.nodes[size_t(n.parent)].cell, b = n.cell;
    (onMain[i] && onMain[size_t(n.parent)] ? main : branches)
        .push_back({float(a.x) + 0.5f, float(a.y) + 0.5f, float(b.x) + 0.5f, float(b.y) + 0.5f});
  }
  sheet.titles.push_back(title);
  sheet.branches.push_back(std::move(branches));
  sheet.main.push_back(std::move(main));
}

void addObstacles(Sheet& sheet, const std::vector<uint8_t>& obstacles) {
  if (obstacles.empty()) return;
  for (int y = 0; y < sheet.height; ++y)
    for (int x = 0; x < sheet.width; ++x) {
      if (!obstacles[size_t(y) * size_t(sheet.width) + size_t(x)]) continue;
      int run = x;
      while (run < sheet.width && obstacles[size_t(y) * size_t(sheet.width) + size_t(run)]) ++run;
      sheet.obstacles.push_back({x, y, run - x, 1});
      x = run;
    }
}

bool drawSheet(const Sheet& sheet, const fs::path& dir) {
  const fs::path data = dir / (sheet.id + ".dat"), script = dir / (sheet.id + ".gp");
  std::ofstream d(data);
  auto block = [&](const std::vector<std::array<float, 4>>& segments) {
    for (const auto& e : segments) d << e[0] << " " << e[1] << " " << e[2] - e[0] << " " << e[3] - e[1] << "\n";
    if (segments.empty()) d << "0 0 0 0\n";  // every index exists: gnuplot counts blank-line pairs
    d << "\n\n";
  };
  for (size_t i = 0; i < sheet.titles.size(); ++i) block(sheet.branches[i]), block(sheet.main[i]);
  d.close();
  const int rows = int((sheet.titles.size() + size_t(sheet.columns) - 1) / size_t(sheet.columns));
  const double aspect = double(sheet.height) / double(sheet.width);
  const int panel = 960 / sheet.columns, w = panel * sheet.columns, h = int(panel * aspect * rows) + 40 * rows + 30;
  std::ofstream g(script);
  g << "set terminal pngcairo noenhanced background rgb 'black' size " << w << "," << h << " font 'sans,9'\n"
    << "set output '" << (dir / (sheet.id + ".png")).string() << "'\n"
    << "set multiplot layout " << rows << "," << sheet.columns << " title \"" << sheet.caption << "\" tc rgb 'white'\n"
    << "unset key\nunset tics\nset border lc rgb '#404040'\nset size ratio -1\nset lmargin 0.5\nset rmargin 0.5\n"
    << "set xrange [0:" << sheet.width << "]\nset yrange [" << sheet.height << ":0]\n";
  for (const auto& o : sheet.obstacles)  // objects stay for every panel of the multiplot
    g << "set object rect from " << o[0] << "," << o[1] << " to " << o[0] + o[2] << "," << o[1] + o[3]
      << " fc rgb '#505050' fs solid noborder behind\n";
  for (size_t i = 0; i < sheet.titles.size(); ++i)
    g << "set title '" << sheet.titles[i] << "' tc rgb 'white'\n"
      << "plot '" << data.string() << "' index " << 2 * i << " with vectors nohead lc rgb '#7fa8ff' lw 1, '' index "
      << 2 * i + 1 << " with vectors nohead lc rgb 'white' lw 2\n";
  g << "unset multiplot\n";
  g.close();
  const std::string cmd = "gnuplot '" + script.string() + "'";
  const bool ok = std::system(cmd.c_str()) == 0;
  if (!ok) std::fprintf(stderr, "error_report: gnuplot failed for %s\n", sheet.id.c_str());
  fs::remove(data);
  fs::remove(script);
  return ok;
}

}  // namespace report
