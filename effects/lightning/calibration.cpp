// The fast method's calibration against DBM (calibration.h): the one place its numbers are written.
// Sections in quotes are docs/lightning-calibration-history.md's, where each number was measured.
#include "calibration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "effects/lightning.h"

namespace effects::lightning {

namespace {

// Below the table, eqn 8's base follows a law in the grid's longest side L (at least 3) and eta:
// ln base = (c + slope min(eta, etaCap)) (ref / L)^power; radius 1, candidates never expire.
struct BaseLaw {
  double c, slope, etaCap, ref, power;
  double base(double longest, double eta) const {
    return std::exp((c + slope * std::min(eta, etaCap)) * std::pow(ref / longest, power));
  }
};
constexpr BaseLaw kLaw4{0.155, 0.06, 3.0, 128.0, 0.35};  // 2-D, 4-neighbourhood ("The 4-neighbourhood")
constexpr BaseLaw kLaw3d26{0.25, 0.0, 0.0, 32.0, 0.6};   // 3-D, 26-neighbourhood ("3-D grids: a base per voxel")
constexpr BaseLaw kLaw3d6{0.32, 0.0, 0.0, 32.0, 0.55};   // 3-D, 6-neighbourhood ("3-D grids: a base per voxel")
// 2-D, 8-neighbourhood below the table: kCalibratedAxisGrowth8 (lightning.h; "Candidates that never expire").

// kCharges: Kim et al.'s power = coef eta^etaPower (L / ref)^sidePower ("The charges method").
struct ChargesLaw {
  double coef, etaPower, ref, sidePower;
};
constexpr ChargesLaw kChargesLaw{5.2, 0.7, 128.0, 0.2};

// The grid side from which N is counted within a radius and the table below holds ("Screening counted within a radius"):
// 256 in the 8-neighbourhood, 512 in the 4-neighbourhood (whose adjacent-cell law still meets
// DBM at 256^2).
constexpr int kTableFrom8 = 256, kTableFrom4 = 512;
int radiusFrom(const Params& p) { return p.neighbourhood == 4 ? kTableFrom4 : kTableFrom8; }

// "A base per grid and η from 512² up" to "The 4-neighbourhood beyond 512²": what meets DBM per
// grid side (a row: 256, 512, 1024) and eta (a column: kTableEtas), measured against DBM's
// bolts: eqn 8's base per cell, the radius N is counted within, and the candidates' lifetime
// (0 = forever).
struct Setting {
  double base;
  int radius;
  int lifetime;
};
constexpr double kTableEtas[] = {0.5, 1, 2, 3, 4};
constexpr int kTableColumns = 5;
template <size_t Rows>
using Table = std::array<std::array<Setting, kTableColumns>, Rows>;
// "A base per grid and η from 512² up" (N within radius 3, candidates that never expire). Grids with obstacles keep it
// whole: a finite lifetime there makes the guide's legs revive their frontier again and again
// (a 1024^2 maze of five walls grew 634 000 cells in 12 s at eta 1 with 1.035, 7, 100).
// At eta 3, N within radius 2 up to 512^2 ("Feet": radius 3 left D 0.04 low at 362^2).
constexpr Table<3> kTable8Obstructed = {{
    {{{1.13, 3, 0}, {1.13, 3, 0}, {1.13, 3, 0}, {1.13, 2, 0}, {1.13, 3, 0}}},      // 256^2
    {{{1.085, 3, 0}, {1.095, 3, 0}, {1.095, 3, 0}, {1.115, 2, 0}, {1.11, 3, 0}}},  // 512^2
    {{{1.08, 3, 0}, {1.08, 3, 0}, {1.08, 3, 0}, {1.09, 3, 0}, {1.09, 3, 0}}},      // 1024^2
}};
// Open grids: the same but for 1024^2 at eta 1 ("Low η on the largest grids") and 0.5 ("1024², η 0.5, and the grids between"), where
// candidates that expire (with N counted over a wider square at eta 1) meet DBM.
constexpr Table<3> kTable8 = [] {
  Table<3> t = kTable8Obstructed;
  t[2][0] = {1.015, 3, 300};
  t[2][1] = {1.035, 7, 100};
  return t;
}();
// "Feet": An entry with a foot reaches down to the row below: just above that row it
// runs with its foot, the setting measured there, and towards its own row the base goes linearly
// and the lifetime geometrically in log2 of the side (a lifetime of 0 stays 0); the radius is the
// foot's up to half-way, then the entry's. A foot of base 0 is none. Where an entry differs from
// the row below in radius or lifetime and has no foot, the step is half-way.
constexpr Table<3> kFeet8Obstructed = [] {
  Table<3> t{};
  t[2][3] = {1.11, 3, 0};  // eta 3: radius 3 from 513^2, from "A base per grid and η from 512² up"'s 512^2 base
  return t;
}();
constexpr Table<3> kFeet8 = [] {
  Table<3> t = kFeet8Obstructed;
  t[2][0] = {1.03, 3, 200};
  t[2][1] = {1.065, 7, 100};
  return t;
}();
// A foot stands on a row below its entry, counts N within a radius of at least 1, and its
// candidates expire where its entry's do.
template <size_t Rows>
constexpr bool feetFit(const Table<Rows>& table, const Table<Rows>& feet) {
  for (size_t r = 0; r < Rows; ++r)
    for (size_t c = 0; c < kTableColumns; ++c) {
      const Setting& f = feet[r][c];
      if (f.base > 0 && (r == 0 || f.radius < 1 || (f.lifetime > 0) != (table[r][c].lifetime > 0))) return false;
    }
  return true;
}
// The 4-neighbourhood ("A base per grid and η from 512² up", "Low η on the largest grids", "The 4-neighbourhood beyond 512²"); at 1024^2 eta 4 (and, with obstacles, 0.5 and 1)
// is 512^2's, held.
constexpr Table<2> kTable4Obstructed = {{
    {{{1.08, 5, 0}, {1.08, 5, 0}, {1.095, 3, 0}, {1.125, 3, 0}, {1.125, 3, 0}}},  // 512^2
    {{{1.08, 5, 0}, {1.08, 5, 0}, {1.0875, 3, 0}, {1.09, 2, 0}, {1.125, 3, 0}}},  // 1024^2
}};
constexpr Table<2> kFeet4Obstructed = [] {
  Table<2> t{};
  t[1][2] = {1.105, 2, 0};
  t[1][3] = {1.10, 2, 0};
  return t;
}();
// Open grids: candidates that expire at 1024^2, eta 1 (one DBM bolt), and at eta 0.5 from 512^2
// ("The 4-neighbourhood beyond 512²": 512^2's 1.08 grew 14 % too few cells there; held beyond, eta 1's entry grew 63 %
// too few at 724^2).
constexpr Table<2> kTable4 = [] {
  Table<2> t = kTable4Obstructed;
  t[0][0] = {1.03, 7, 200};
  t[1][0] = {1.0075, 7, 300};
  t[1][1] = {1.015, 7, 75};
  return t;
}();
constexpr Table<2> kFeet4 = [] {
  Table<2> t = kFeet4Obstructed;
  t[1][0] = {1.03, 7, 200};
  t[1][1] = {1.05, 7, 75};
  return t;
}();
static_assert(feetFit(kTable8, kFeet8) && feetFit(kTable8Obstructed, kFeet8Obstructed) && feetFit(kTable4, kFeet4) &&
              feetFit(kTable4Obstructed, kFeet4Obstructed));

// One column's setting at r = log2(side / firstSide) between rows r0 and r1 = r0 + 1 (r0 = r1
// beyond the last row): an entry with a foot over its reach (above); else the nearer row's radius
// and lifetime, with the base linear between rows that share them.
template <size_t Rows>
Setting columnSetting(const Table<Rows>& table, const Table<Rows>& feet, size_t r0, size_t r1, double re, size_t c) {
  const Setting &lo = table[r0][c], &hi = table[r1][c], &foot = feet[r1][c];
  if (r1 > r0 && foot.base > 0 && re > 0) {
    const double lifetime = hi.lifetime ? foot.lifetime * std::pow(double(hi.lifetime) / foot.lifetime, re) : 0;
    return {foot.base + re * (hi.base - foot.base), re <= 0.5 ? foot.radius : hi.radius, int(std::lround(lifetime))};
  }
  if (lo.radius == hi.radius && lo.lifetime == hi.lifetime)
    return {lo.base + re * (hi.base - lo.base), lo.radius, lo.lifetime};
  return re <= 0.5 ? lo : hi;
}

// table[row][column]: rows at sides firstSide, 2 firstSide, ...; in log2 of the side between
// rows (columnSetting) and in eta between columns, held beyond the first and last of each.
// Columns that share the radius and whether candidates expire blend: the base linearly, the
// lifetime geometrically; elsewhere the nearer column's (a step half-way between columns).
template <size_t Rows>
Setting tableSetting(const Table<Rows>& table, const Table<Rows>& feet, double firstSide, double side, double eta) {
  const double r = std::clamp(std::log2(side / firstSide), 0.0, double(Rows - 1));
  const size_t r0 = std::min(size_t(r), Rows - 1), r1 = std::min(r0 + 1, Rows - 1);
  const double e = std::clamp(eta, kTableEtas[0], kTableEtas[kTableColumns - 1]);
  size_t c0 = 0;
  while (c0 + 2 < kTableColumns && e > kTableEtas[c0 + 1]) ++c0;
  const double ce = (e - kTableEtas[c0]) / (kTableEtas[c0 + 1] - kTableEtas[c0]), re = r - double(r0);
  const Setting s0 = columnSetting(table, feet, r0, r1, re, c0), s1 = columnSetting(table, feet, r0, r1, re, c0 + 1);
  if (s0.radius == s1.radius && (s0.lifetime > 0) == (s1.lifetime > 0)) {
    const double lifetime = s0.lifetime ? s0.lifetime * std::pow(double(s1.lifetime) / s0.lifetime, ce) : 0;
    return {s0.base + ce * (s1.base - s0.base), s0.radius, int(std::lround(lifetime))};
  }
  return ce <= 0.5 ? s0 : s1;
}

// The table's setting for a 2-D grid from radiusFrom() up.
Setting largeGridSetting(const Params& p) {
  const double longer = std::max(p.width, p.height);
  const bool open = std::none_of(p.obstacles.begin(), p.obstacles.end(), [](uint8_t o) { return o != 0; });
  if (p.neighbourhood == 4)
    return open ? tableSetting(kTable4, kFeet4, kTableFrom4, longer, p.eta)
                : tableSetting(kTable4Obstructed, kFeet4Obstructed, kTableFrom4, longer, p.eta);
  return open ? tableSetting(kTable8, kFeet8, kTableFrom8, longer, p.eta)
              : tableSetting(kTable8Obstructed, kFeet8Obstructed, kTableFrom8, longer, p.eta);
}

bool fromTable(const Params& p) { return !p.depth && std::max(p.width, p.height) >= radiusFrom(p); }

// The calibrated setting of a grid, from one look at its obstacles: the table's from radiusFrom()
// up (its radius and lifetime for 2-D fast only), else eqn 8's base from the laws above with
// radius 1 and no lifetime.
Setting calibratedSetting(const Params& p) {
  if (p.depth) {
    const double longest = std::max({3, p.width, p.height, p.depth});
    return {(p.neighbourhood == 6 ? kLaw3d6 : kLaw3d26).base(longest, p.eta), 1, 0};
  }
  if (fromTable(p)) {
    const Setting s = largeGridSetting(p);
    return p.method == Method::kFast ? s : Setting{s.base, 1, 0};
  }
  if (p.neighbourhood != 4) return {kCalibratedAxisGrowth8, 1, 0};
  const double longer = std::max(3, std::max(p.width, p.height));
  return {kLaw4.base(longer, p.eta), 1, 0};
}

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d, e);
  return buf;
}

std::string settingText(const Setting& s) {
  std::string t = format("%g", s.base);
  if (s.radius != 1) t += format(", r %g", s.radius);
  if (s.lifetime) t += format(", life %g", s.lifetime);
  return t;
}

template <size_t Rows>
std::string tableMarkdown(const char* title, const Table<Rows>& table, const Table<Rows>& feet, int firstSide) {
  std::string md = std::string("\n### ") + title + "\n\n| side |";
  for (double eta : kTableEtas) md += format(" η %g |", eta);
  md += "\n|---|";
  for (int c = 0; c < kTableColumns; ++c) md += "---|";
  for (size_t r = 0; r < Rows; ++r) {
    md += format("\n| %g² |", firstSide << r);
    for (size_t c = 0; c < kTableColumns; ++c) {
      md += " " + settingText(table[r][c]);
      if (feet[r][c].base > 0) md += format("; foot at %g²: ", (firstSide << (r - 1)) + 1) + settingText(feet[r][c]);
      md += " |";
    }
  }
  return md + "\n";
}

std::string lawText(const BaseLaw& l) {
  const std::string factor = l.slope ? format("(%g + %g min(η, %g))", l.c, l.slope, l.etaCap) : format("%g", l.c);
  return "ln base = " + factor + format(" (%g / L)^%g", l.ref, l.power);
}

}  // namespace

double calibratedAxisGrowth(const Params& p) { return calibratedSetting(p).base; }

int calibratedScreeningRadius(const Params& p) { return calibratedSetting(p).radius; }

int calibratedLifetime(const Params& p) { return calibratedSetting(p).lifetime; }

void calibrate(Params& p) {
  const Setting s = calibratedSetting(p);
  p.axisGrowth = s.base;
  p.lifetime = s.lifetime;
}

void usePaperConstants(Params& p) {
  p.lifetime = kPaperLifetime;
  p.axisGrowth = kPaperAxisGrowth;
  p.chargesEta = p.eta;
  p.screeningRadius = 1;
}

int screeningRadius(const Params& p) {
  if (p.method != Method::kFast || p.depth) return 1;
  return p.screeningRadius > 0 ? p.screeningRadius : calibratedScreeningRadius(p);
}

double calibratedChargesEta(const Params& p) {
  const double longer = std::max(3, std::max(p.width, p.height));
  return kChargesLaw.coef * std::pow(p.eta, kChargesLaw.etaPower) * std::pow(longer / kChargesLaw.ref, kChargesLaw.sidePower);
}

std::string calibrationMarkdown() {
  std::string md =
      "What `variant: \"calibrated\"` (the default) runs. A setting is eqn 8's base per cell, the radius\n"
      "eqn 6's N is counted within (r, 1 when not shown) and the candidates' lifetime in steps (life;\n"
      "never expire when not shown). L is the grid's longer side (longest in 3-D, at least 3).\n\n"
      "### Below the table\n\n"
      "| grid | setting |\n|---|---|\n" +
      format("| 2-D, 8-neighbourhood, L < %g | base %g |\n", kTableFrom8, kCalibratedAxisGrowth8) +
      format("| 2-D, 4-neighbourhood, L < %g | ", kTableFrom4) + lawText(kLaw4) + " |\n" +
      "| 3-D, 26-neighbourhood | " + lawText(kLaw3d26) + " |\n" + "| 3-D, 6-neighbourhood | " +
      lawText(kLaw3d6) + " |\n" +
      format("| charges (Kim et al.'s power) | %g η^%g (L / %g)^%g |\n", kChargesLaw.coef, kChargesLaw.etaPower,
             kChargesLaw.ref, kChargesLaw.sidePower) +
      "\nThe dbm and charges methods take only the base (no radius or lifetime) where they use one.\n";
  md += tableMarkdown("2-D, 8-neighbourhood, open grid", kTable8, kFeet8, kTableFrom8);
  md += tableMarkdown("2-D, 8-neighbourhood, grid with obstacles", kTable8Obstructed, kFeet8Obstructed, kTableFrom8);
  md += tableMarkdown("2-D, 4-neighbourhood, open grid", kTable4, kFeet4, kTableFrom4);
  md += tableMarkdown("2-D, 4-neighbourhood, grid with obstacles", kTable4Obstructed, kFeet4Obstructed, kTableFrom4);
  md +=
      "\n### Between rows and columns\n\n"
      "- Beyond the first and last row and column, the nearest one holds.\n"
      "- Between two rows (in log2 of L): an entry with a foot runs, just above the row below, with\n"
      "  its foot; towards its own row the base goes linearly and the lifetime geometrically; the\n"
      "  radius is the foot's up to half-way, then the entry's. Without a foot, rows that share\n"
      "  radius and lifetime blend the base linearly; otherwise the nearer row's setting holds.\n"
      "- Between two columns (in η): settings that share the radius and whether candidates expire\n"
      "  blend, the base linearly and the lifetime geometrically; otherwise the nearer column's.\n";
  md += "\n### What that gives, open 8-neighbourhood grids (square, L × L)\n\n| L |";
  constexpr double kEtas[] = {0.5, 0.75, 1, 1.5, 2, 3, 4};
  constexpr int kSides[] = {64, 128, 255, 256, 362, 512, 513, 724, 1024, 2048};
  for (double eta : kEtas) md += format(" η %g |", eta);
  md += "\n|---|";
  for (size_t i = 0; i < std::size(kEtas); ++i) md += "---|";
  for (int side : kSides) {
    md += format("\n| %g |", side);
    for (double eta : kEtas) {
      Params p;
      p.width = p.height = side;
      p.eta = eta;
      md += " " + settingText(calibratedSetting(p)) + " |";
    }
  }
  return md + "\n";
}

}  // namespace effects::lightning
