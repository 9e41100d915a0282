/* svgplot_demo — draws the two kinds of figure the phgmg examples produce,
   from synthetic data, with examples/svgplot.h:
     svgplot_demo_r.svg  two panels, error against the reduced dimension r
                         (one series has a failed run, a NaN, which breaks
                         its line), markers on every series;
     svgplot_demo_t.svg  one panel, error against time t = 0..100 (1001
                         points), with a fixed y range.
   Usage: svgplot_demo [outdir]   (default: the current directory)
   Build: cc -std=c99 -O2 examples/svgplot_demo.c -o build/svgplot_demo -lm */
#include "svgplot.h"

int main(int argc, char **argv) {
  const char *dir = argc > 1 ? argv[1] : ".";
  char path[1024];
  double r[9], e[3][9], t[1001], et[3][1001];
  const char *names[3] = {"POD-Galerkin", "SP1", "GMG-POD"};
  const double rate[2][3] = {{0.22, 0.30, 0.45}, {0.25, 0.35, 0.55}};
  svgplot_fig *f;
  int i, k, pnl, rc = 0;

  f = svgplot_new("Relative output error of the reduced models", 2);
  if (!f) return 1;
  svgplot_panel(f, 0, "(a) u = 0.1 sin t", "reduced dimension r", "relative error");
  svgplot_panel(f, 1, "(b) u = 0.1", "reduced dimension r", "relative error");
  for (pnl = 0; pnl < 2; ++pnl) {
    for (i = 0; i < 9; ++i) {
      r[i] = 4 + 2 * i;
      for (k = 0; k < 3; ++k)
        e[k][i] = 2.0 * pow(10.0, -rate[pnl][k] * r[i]) * (1 + 0.3 * sin(i + k));
    }
    if (pnl == 0) e[1][4] = NAN; /* a failed SP1 run: the line breaks there */
    for (k = 0; k < 3; ++k)
      svgplot_series(f, pnl, names[k], 9, r, e[k], k | SVGPLOT_MARKERS);
  }
  snprintf(path, sizeof path, "%s/svgplot_demo_r.svg", dir);
  if (svgplot_save(f, path) != 0) { fprintf(stderr, "cannot write %s\n", path); rc = 1; }
  else printf("wrote %s\n", path);
  svgplot_free(f);

  f = svgplot_new("Error along the trajectory, r = 10", 1);
  if (!f) return 1;
  svgplot_panel(f, 0, "u = 0.1 sin t", "time t", "|y - y_r| / max |y|");
  for (i = 0; i <= 1000; ++i) {
    t[i] = 0.1 * i;
    for (k = 0; k < 3; ++k)
      et[k][i] = pow(10.0, -2.0 - 1.5 * k) * (1 - exp(-t[i] / 5)) * fabs(sin(0.5 * t[i] + k));
  }
  for (k = 0; k < 3; ++k) svgplot_series(f, 0, names[k], 1001, t, et[k], k);
  svgplot_yrange(f, 0, 1e-8, 1e-1);
  snprintf(path, sizeof path, "%s/svgplot_demo_t.svg", dir);
  if (svgplot_save(f, path) != 0) { fprintf(stderr, "cannot write %s\n", path); rc = 1; }
  else printf("wrote %s\n", path);
  svgplot_free(f);
  return rc;
}
