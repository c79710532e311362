// The soap bubble's thin-film colour table, per count of wavelength bands, against the
// spectral quadrature; and Belcour & Barla's analytic form, which a shader could evaluate.
#include <effects/bubble.h>

#include "sections.h"

namespace report {

namespace {

namespace bb = effects::bubble;

volatile double sink = 0;

void measure(Run& run) {
  const int side = run.quick ? 64 : 256;
  for (int w : run.quick ? std::vector<int>{3, 8, 16} : std::vector<int>{3, 4, 5, 6, 8, 11, 16, 23, 32, 45, 64, 81, 128, 200, 400}) {
    for (const bool thick : {false, true}) {
      bb::ThinFilmOptions o;
      o.width = o.height = side;
      o.wavelengths = w;
      if (thick) o.thicknessMinNm = 99000, o.thicknessMaxNm = 100000;  // fringes finer than 1 nm
      o.measureError = false;
      Row r;
      r.series = thick ? "Airy bands, 99-100 um" : "Airy bands, 0-1000 nm";
      r.setting = std::to_string(w);
      r.group = thick ? "films of 99-100 um" : "films of 0-1000 nm";  // a client's film fixes it
      r.request = {{"thinFilm", {{"wavelengths", w}}}};
      r.ticket = run.repeat("thin film " + std::to_string(w), run.quick ? 3 : 5, [o] { (void)bb::thinFilmTable(o); });
      o.measureError = true;  // the same table: its texels at a 32 x 32 sub-grid against the reference
      auto t = bb::thinFilmTable(o);
      r.errors["meanDeltaE"] = t.value().meanDeltaE;
      r.note = fmt(t.value().maxDeltaE, 3);
      run.rows.push_back(r);
    }
  }
  // The analytic form's colours at 64 thicknesses x 32 angles over 0-1000 nm against the same
  // reference, timed for as many colours as the table holds.
  std::vector<double> de;
  for (int b = 0; b < 32; ++b)
    for (int a = 0; a < 64; ++a) {
      const double d = 1000.0 * (a + 0.5) / 64, c = 0.02 + 0.98 * (b + 0.5) / 32;
      de.push_back(bb::deltaE(bb::filmColorAnalytic(1.33, d, c), bb::filmColorReference(1.33, d, c)));
    }
  double mean = 0;
  for (double d : de) mean += d;
  Row r;
  r.series = "analytic (Belcour & Barla 2017), 0-1000 nm";
  r.setting = "closed form";
  r.group = "films of 0-1000 nm";
  r.errors["meanDeltaE"] = mean / double(de.size());
  r.note = fmt(quantile(de, 1.0), 3) + " (in a shader: no request field)";
  r.ticket = run.repeat("thin film analytic", run.quick ? 3 : 5, [side] {
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) sink = sink + bb::filmColorAnalytic(1.33, 1000.0 * i / side, (j + 0.5) / side).x;
  });
  run.rows.push_back(r);
}

std::string conclude(const Section&, const Run& run) {
  const Row* jnd = fastestWithin(run, "meanDeltaE", 1.0);
  if (!jnd) return "";
  return "Fewest bands with a mean ΔE below 1 (about one just-noticeable difference): " + jnd->setting + " (" +
         jnd->series + ") at " + fmt(jnd->ms) + " ms per table; effectd's default is 16. At 99-100 um every count is "
         "the incoherent grey within ΔE 1: the band means do not alias.";
}

}  // namespace

Section thinFilmSection() {
  Section s;
  s.id = "thin-film";
  s.effect = "bubble";
  s.title = "Soap bubble: thin-film colour table against the spectral quadrature, films of 0-1000 nm and 99-100 um";
  s.reference =
      "the spectral integral by Gauss-Legendre quadrature resolving every fringe (filmColorReference) at a 32 x 32 "
      "sub-grid of the timed table's own texels";
  s.metrics = {{"meanDeltaE", "ΔE", "mean CIE76 ΔE*ab", 2.3, "mean Delta E 2.3, one just-noticeable difference"}};
  s.timeName = "ms per 256² table (median; 64² in the quick run)";
  s.settingName = "wavelength samples";
  s.noteName = "max ΔE*ab";
  s.code = {"effects/bubble"};
  s.asks = {{"films of 0-1000 nm", "a soap-film colour table (256², films of 0-1000 nm)"}};
  s.measure = measure;
  s.conclude = conclude;
  return s;
}

}  // namespace report
