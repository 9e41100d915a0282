/* svgplot.h — a tiny single-header SVG plotter for the phgmg example figures.
   C99, no dependencies beyond stdio/stdlib/string/math; every function is
   static, so include it wherever it is used.

   A figure is one or more panels side by side under an overall title. Each
   panel has a linear x axis with integer ticks (r = 4..20, t = 0..100) and a
   logarithmic y axis with a gridline and a label (10^k) at every decade.
   Series are polylines with a colour, dash pattern and (optionally) markers
   chosen by a style index; points with a NaN/Inf coordinate or y <= 0 are
   skipped and break the line. One legend under the panels names every
   distinct series once. The y range is the whole decades enclosing the data
   unless set by svgplot_yrange.

       svgplot_fig *f = svgplot_new("Errors of the reduced models", 2);
       svgplot_panel(f, 0, "(a) u = 0.1 sin t", "r", "relative error");
       svgplot_series(f, 0, "GMG-POD", n, r, err, 0 | SVGPLOT_MARKERS);
       ...
       if (svgplot_save(f, "results/fig.svg") != 0) ...;
       svgplot_free(f);

   Style index s (0..7, wraps): colour and dash pattern, see svgplot__styles;
   add SVGPLOT_MARKERS to draw a marker at the points (thinned to at most 40
   per series). Default size: 550 px wide per panel, 450 px high (plus a line
   per extra legend row); fonts 13-18 px. */
#ifndef SVGPLOT_H
#define SVGPLOT_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SVGPLOT_MARKERS 0x100 /* add to a style index: draw markers */

/* Every function is static and marked unused, so a file that uses only some
   of them compiles warning-free. */
#if defined(__GNUC__) || defined(__clang__)
#define SVGPLOT_FN static __attribute__((unused))
#else
#define SVGPLOT_FN static
#endif

typedef struct svgplot__series {
  char *name;
  int n, style;
  double *x, *y;
} svgplot__series;

typedef struct svgplot__panel {
  char *title, *xlabel, *ylabel;
  svgplot__series *s;
  int ns, cap;
  int manual_y;
  double ymin, ymax;
} svgplot__panel;

typedef struct svgplot_fig {
  char *title;
  int np, width, height; /* width/height 0 = default */
  svgplot__panel *p;
} svgplot_fig;

typedef struct svgplot__style {
  const char *color, *dash;
  int marker; /* 0 circle, 1 square, 2 triangle, 3 diamond */
} svgplot__style;

/* Colour-blind-safe palette (Okabe & Ito) with distinct dash patterns. */
static const svgplot__style svgplot__styles[8] = {
  {"#0072B2", "", 0},          {"#D55E00", "9 4", 1},     {"#009E73", "10 3 2 3", 2},
  {"#CC79A7", "2 3", 3},       {"#E69F00", "14 4", 0},    {"#56B4E9", "6 3 6 3 1 3", 1},
  {"#000000", "4 2", 2},       {"#7F7F7F", "1 2", 3}};

SVGPLOT_FN char *svgplot__strdup(const char *s) {
  size_t n = strlen(s ? s : "");
  char *d = (char *)malloc(n + 1);
  if (d) memcpy(d, s ? s : "", n + 1);
  return d;
}

/* Free a figure and everything it holds (NULL is a no-op). */
SVGPLOT_FN void svgplot_free(svgplot_fig *f) {
  int i, k;
  if (!f) return;
  for (i = 0; i < f->np && f->p; ++i) {
    svgplot__panel *p = &f->p[i];
    free(p->title); free(p->xlabel); free(p->ylabel);
    for (k = 0; k < p->ns; ++k) { free(p->s[k].name); free(p->s[k].x); free(p->s[k].y); }
    free(p->s);
  }
  free(f->p);
  free(f->title);
  free(f);
}

/* A new figure with npanels (>= 1) empty panels; NULL on bad input or OOM. */
SVGPLOT_FN svgplot_fig *svgplot_new(const char *title, int npanels) {
  svgplot_fig *f;
  if (npanels < 1 || npanels > 16) return NULL;
  f = (svgplot_fig *)calloc(1, sizeof *f);
  if (!f) return NULL;
  f->np = npanels;
  f->title = svgplot__strdup(title);
  f->p = (svgplot__panel *)calloc((size_t)npanels, sizeof *f->p);
  if (!f->title || !f->p) { svgplot_free(f); return NULL; }
  return f;
}

/* Overall size in pixels (0 = default: 550 per panel x 450). */
SVGPLOT_FN void svgplot_size(svgplot_fig *f, int width, int height) {
  if (!f) return;
  f->width = width > 0 ? width : 0;
  f->height = height > 0 ? height : 0;
}

/* Title and axis labels of panel i. Returns 0, or -1 on a bad index / OOM. */
SVGPLOT_FN int svgplot_panel(svgplot_fig *f, int i, const char *title, const char *xlabel,
                             const char *ylabel) {
  svgplot__panel *p;
  char *t, *x, *y;
  if (!f || i < 0 || i >= f->np) return -1;
  p = &f->p[i];
  t = svgplot__strdup(title); x = svgplot__strdup(xlabel); y = svgplot__strdup(ylabel);
  if (!t || !x || !y) { free(t); free(x); free(y); return -1; }
  free(p->title); free(p->xlabel); free(p->ylabel);
  p->title = t; p->xlabel = x; p->ylabel = y;
  return 0;
}

/* Fix the y range of panel i to [ymin, ymax] (0 < ymin < ymax); data outside
   is clipped. Returns 0 or -1. */
SVGPLOT_FN int svgplot_yrange(svgplot_fig *f, int i, double ymin, double ymax) {
  if (!f || i < 0 || i >= f->np || !(ymin > 0) || !(ymax > ymin) || !isfinite(ymax)) return -1;
  f->p[i].manual_y = 1;
  f->p[i].ymin = ymin;
  f->p[i].ymax = ymax;
  return 0;
}

/* Add a series of n points (x[k], y[k]) to panel i (copied). style: index
   0..7 (wraps), plus SVGPLOT_MARKERS for markers. Returns 0 or -1. */
SVGPLOT_FN int svgplot_series(svgplot_fig *f, int i, const char *name, int n, const double *x,
                              const double *y, int style) {
  svgplot__panel *p;
  svgplot__series *s;
  if (!f || i < 0 || i >= f->np || n < 0 || (n > 0 && (!x || !y)) || style < 0) return -1;
  p = &f->p[i];
  if (p->ns == p->cap) {
    int nc = p->cap ? 2 * p->cap : 4;
    svgplot__series *ns = (svgplot__series *)realloc(p->s, (size_t)nc * sizeof *ns);
    if (!ns) return -1;
    p->s = ns;
    p->cap = nc;
  }
  s = &p->s[p->ns];
  s->name = svgplot__strdup(name);
  s->x = (double *)malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
  s->y = (double *)malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
  if (!s->name || !s->x || !s->y) { free(s->name); free(s->x); free(s->y); return -1; }
  if (n > 0) {
    memcpy(s->x, x, (size_t)n * sizeof(double));
    memcpy(s->y, y, (size_t)n * sizeof(double));
  }
  s->n = n;
  s->style = style;
  p->ns++;
  return 0;
}

/* ---- drawing ---- */

SVGPLOT_FN void svgplot__esc(FILE *o, const char *s) {
  for (; s && *s; ++s) {
    switch (*s) {
      case '&': fputs("&amp;", o); break;
      case '<': fputs("&lt;", o); break;
      case '>': fputs("&gt;", o); break;
      case '"': fputs("&quot;", o); break;
      default: fputc(*s, o);
    }
  }
}

/* Rough text width in px for the legend layout (sans-serif, ~0.58 em/char). */
SVGPLOT_FN double svgplot__textw(const char *s, double fs) {
  return 0.58 * fs * (double)strlen(s ? s : "");
}

SVGPLOT_FN int svgplot__ok(double x, double y) { return isfinite(x) && isfinite(y) && y > 0; }

SVGPLOT_FN void svgplot__marker(FILE *o, int kind, double x, double y, const char *color) {
  const double r = 4.0;
  switch (kind) {
    case 0:
      fprintf(o, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.1f\" fill=\"white\" stroke=\"%s\"/>",
              x, y, r, color);
      break;
    case 1:
      fprintf(o, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.1f\" height=\"%.1f\" fill=\"white\" "
                 "stroke=\"%s\"/>", x - r, y - r, 2 * r, 2 * r, color);
      break;
    case 2:
      fprintf(o, "<path d=\"M%.2f %.2fL%.2f %.2fL%.2f %.2fZ\" fill=\"white\" stroke=\"%s\"/>",
              x, y - 1.2 * r, x + 1.1 * r, y + 0.8 * r, x - 1.1 * r, y + 0.8 * r, color);
      break;
    default:
      fprintf(o, "<path d=\"M%.2f %.2fL%.2f %.2fL%.2f %.2fL%.2f %.2fZ\" fill=\"white\" "
                 "stroke=\"%s\"/>", x, y - 1.3 * r, x + 1.3 * r, y, x, y + 1.3 * r, x - 1.3 * r, y,
              color);
  }
}

/* Sample of a style (line + marker) at (x, y), 36 px long. */
SVGPLOT_FN void svgplot__sample(FILE *o, int style, double x, double y) {
  const svgplot__style *st = &svgplot__styles[(style & 0xff) % 8];
  fprintf(o, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
             "stroke-width=\"2.2\"%s%s%s/>",
          x, y, x + 36, y, st->color, *st->dash ? " stroke-dasharray=\"" : "", st->dash,
          *st->dash ? "\"" : "");
  if (style & SVGPLOT_MARKERS) svgplot__marker(o, st->marker, x + 18, y, st->color);
}

/* A "nice" integer tick step (1, 2, 5 x 10^k, at least 1) for a span. */
SVGPLOT_FN double svgplot__xstep(double span, int maxticks) {
  double step = 1.0;
  if (maxticks < 2) maxticks = 2;
  for (;;) {
    if (span / step <= maxticks) return step;
    if (span / (2 * step) <= maxticks) return 2 * step;
    if (span / (5 * step) <= maxticks) return 5 * step;
    step *= 10;
  }
}

/* 10^k label with a superscript (U+2212 minus). */
SVGPLOT_FN void svgplot__pow10(FILE *o, double x, double y, int k, const char *anchor) {
  fprintf(o, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"%s\" font-size=\"14\">10"
             "<tspan dy=\"-7\" font-size=\"12\">%s%d</tspan></text>\n",
          x, y, anchor, k < 0 ? "\xE2\x88\x92" : "", k < 0 ? -k : k);
}

SVGPLOT_FN void svgplot__draw_panel(FILE *o, const svgplot__panel *p, int idx, double L,
                                    double T, double R, double B) {
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL, lo, hi;
  double xlo, xhi, step, t, pw = R - L, ph = B - T;
  int k, j, dlo, dhi, dstep, any = 0;
  for (k = 0; k < p->ns; ++k)
    for (j = 0; j < p->s[k].n; ++j) {
      double x = p->s[k].x[j], y = p->s[k].y[j];
      if (!svgplot__ok(x, y)) continue;
      any = 1;
      if (x < xmin) xmin = x;
      if (x > xmax) xmax = x;
      if (y < ymin) ymin = y;
      if (y > ymax) ymax = y;
    }
  if (!any) { xmin = 0; xmax = 1; ymin = 0.1; ymax = 1; }
  if (xmax == xmin) { xmin -= 1; xmax += 1; }
  if (p->manual_y) { lo = log10(p->ymin); hi = log10(p->ymax); }
  else {
    lo = floor(log10(ymin));
    hi = ceil(log10(ymax));
    if (hi <= lo) hi = lo + 1;
  }
  /* x range: the data plus 2% each side so end markers are not cut */
  xlo = xmin - 0.02 * (xmax - xmin);
  xhi = xmax + 0.02 * (xmax - xmin);
#define SVGPLOT__X(v) (L + ((v) - xlo) / (xhi - xlo) * pw)
#define SVGPLOT__Y(v) (B - (log10(v) - lo) / (hi - lo) * ph)
  fprintf(o, "<g id=\"panel%d\">\n", idx);
  fprintf(o, "<clipPath id=\"clip%d\"><rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" "
             "height=\"%.1f\"/></clipPath>\n", idx, L, T, pw, ph);
  fprintf(o, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"white\"/>\n",
          L, T, pw, ph);
  /* y gridlines: minor (2..9 x 10^k) when few decades, major at each decade */
  dlo = (int)ceil(lo - 1e-9);
  dhi = (int)floor(hi + 1e-9);
  /* label every decade, or every 2nd/5th/10th/... when they would crowd */
  {
    static const int nice[10] = {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000};
    for (j = 0; j < 9 && (double)(dhi - dlo) / nice[j] > ph / 22.0; ++j) {}
    dstep = nice[j];
  }
  if (hi - lo <= 8) {
    fputs("<path stroke=\"#ececec\" stroke-width=\"1\" d=\"", o);
    for (k = dlo - 1; k <= dhi; ++k)
      for (j = 2; j <= 9; ++j) {
        double lv = k + log10((double)j);
        if (lv <= lo || lv >= hi) continue;
        t = B - (lv - lo) / (hi - lo) * ph;
        fprintf(o, "M%.1f %.2fH%.1f", L, t, R);
      }
    fputs("\"/>\n", o);
  }
  for (k = dlo; k <= dhi; ++k) {
    t = B - (k - lo) / (hi - lo) * ph;
    if (((k % dstep) + dstep) % dstep == 0) {
      fprintf(o, "<line x1=\"%.1f\" y1=\"%.2f\" x2=\"%.1f\" y2=\"%.2f\" stroke=\"#c8c8c8\"/>\n",
              L, t, R, t);
      svgplot__pow10(o, L - 7, t + 5, k, "end");
    }
  }
  /* x ticks: integers, nice step */
  step = svgplot__xstep(xmax - xmin, (int)(pw / 42.0));
  for (t = ceil(xmin / step) * step; t <= xmax + 1e-9 * step; t += step) {
    double px = SVGPLOT__X(t);
    fprintf(o, "<line x1=\"%.2f\" y1=\"%.1f\" x2=\"%.2f\" y2=\"%.1f\" stroke=\"#ececec\"/>\n",
            px, T, px, B);
    fprintf(o, "<line x1=\"%.2f\" y1=\"%.1f\" x2=\"%.2f\" y2=\"%.1f\" stroke=\"#333\"/>\n",
            px, B, px, B + 5);
    fprintf(o, "<text x=\"%.2f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"14\">%.0f</text>\n",
            px, B + 21, t == 0 ? 0.0 : t);
  }
  /* series */
  fprintf(o, "<g clip-path=\"url(#clip%d)\" fill=\"none\" stroke-width=\"2.2\" "
             "stroke-linejoin=\"round\">\n", idx);
  for (k = 0; k < p->ns; ++k) {
    const svgplot__series *s = &p->s[k];
    const svgplot__style *st = &svgplot__styles[(s->style & 0xff) % 8];
    int pen = 0, nok = 0, every;
    fprintf(o, "<path stroke=\"%s\"", st->color);
    if (*st->dash) fprintf(o, " stroke-dasharray=\"%s\"", st->dash);
    fputs(" d=\"", o);
    for (j = 0; j < s->n; ++j) {
      if (!svgplot__ok(s->x[j], s->y[j])) { pen = 0; continue; }
      fprintf(o, "%c%.2f %.2f", pen ? 'L' : 'M', SVGPLOT__X(s->x[j]), SVGPLOT__Y(s->y[j]));
      pen = 1;
      ++nok;
    }
    fputs("\"/>\n", o);
    if ((s->style & SVGPLOT_MARKERS) && nok > 0) {
      every = (nok + 39) / 40;
      for (j = 0, nok = 0; j < s->n; ++j) {
        if (!svgplot__ok(s->x[j], s->y[j])) continue;
        if (nok++ % every) continue;
        svgplot__marker(o, st->marker, SVGPLOT__X(s->x[j]), SVGPLOT__Y(s->y[j]), st->color);
      }
      fputc('\n', o);
    }
  }
  fputs("</g>\n", o);
#undef SVGPLOT__X
#undef SVGPLOT__Y
  /* frame, titles, labels */
  fprintf(o, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
             "stroke=\"#333\"/>\n", L, T, pw, ph);
  if (p->title && *p->title) {
    fprintf(o, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"16\">",
            (L + R) / 2, T - 10);
    svgplot__esc(o, p->title);
    fputs("</text>\n", o);
  }
  if (p->xlabel && *p->xlabel) {
    fprintf(o, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"15\">",
            (L + R) / 2, B + 44);
    svgplot__esc(o, p->xlabel);
    fputs("</text>\n", o);
  }
  if (p->ylabel && *p->ylabel) {
    fprintf(o, "<text transform=\"translate(%.1f %.1f) rotate(-90)\" text-anchor=\"middle\" "
               "font-size=\"15\">", L - 58, (T + B) / 2);
    svgplot__esc(o, p->ylabel);
    fputs("</text>\n", o);
  }
  fputs("</g>\n", o);
}

/* Write the figure as SVG to path. Returns 0, or -1 if the file cannot be
   written. */
SVGPLOT_FN int svgplot_save(const svgplot_fig *f, const char *path) {
  /* distinct legend entries (name + style), in order of first appearance */
  const char *names[64];
  int styles[64], nleg = 0, i, k, j, rows = 1, err;
  double W, H, x, rowx, top, plotB, legy, pw, lw[64];
  FILE *o;
  if (!f || !path) return -1;
  for (i = 0; i < f->np; ++i)
    for (k = 0; k < f->p[i].ns; ++k) {
      const svgplot__series *s = &f->p[i].s[k];
      if (!s->name || !*s->name) continue;
      for (j = 0; j < nleg; ++j)
        if (styles[j] == s->style && strcmp(names[j], s->name) == 0) break;
      if (j == nleg && nleg < 64) { names[nleg] = s->name; styles[nleg++] = s->style; }
    }
  W = f->width ? f->width : 550.0 * f->np;
  /* legend rows: entries laid out left to right, wrapped at the width */
  rowx = 0;
  for (j = 0; j < nleg; ++j) {
    lw[j] = 36 + 8 + svgplot__textw(names[j], 15) + 28;
    if (rowx > 0 && rowx + lw[j] > W - 60) { rows++; rowx = 0; }
    rowx += lw[j];
  }
  if (nleg == 0) rows = 0;
  H = f->height ? f->height : 450.0 + 26.0 * (rows > 1 ? rows - 1 : 0);
  o = fopen(path, "w");
  if (!o) return -1;
  fprintf(o, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
             "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
             "viewBox=\"0 0 %.0f %.0f\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\" "
             "fill=\"#222\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
          W, H, W, H);
  top = 34;
  if (f->title && *f->title) {
    fprintf(o, "<text x=\"%.1f\" y=\"26\" text-anchor=\"middle\" font-size=\"18\" "
               "font-weight=\"bold\">", W / 2);
    svgplot__esc(o, f->title);
    fputs("</text>\n", o);
    top = 62;
  } else {
    top = 40;
  }
  plotB = H - 84 - 26.0 * (rows > 1 ? rows - 1 : 0);
  pw = W / f->np;
  for (i = 0; i < f->np; ++i)
    svgplot__draw_panel(o, &f->p[i], i, i * pw + 82, top, (i + 1) * pw - 18, plotB);
  /* legend, centred under the panels */
  legy = plotB + 69;
  for (j = 0; j < nleg;) {
    int j0 = j;
    double roww = 0;
    while (j < nleg && (j == j0 || roww + lw[j] <= W - 60)) roww += lw[j++];
    x = (W - roww + 28) / 2;
    for (k = j0; k < j; ++k) {
      svgplot__sample(o, styles[k], x, legy - 5);
      fprintf(o, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"15\">", x + 44, legy);
      svgplot__esc(o, names[k]);
      fputs("</text>\n", o);
      x += lw[k];
    }
    legy += 26;
  }
  fputs("</svg>\n", o);
  err = ferror(o);
  if (fclose(o) != 0 || err) return -1;
  return 0;
}

#endif /* SVGPLOT_H */
