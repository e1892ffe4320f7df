#!/usr/bin/env python3
"""Draws a soak run's RSS samples (scripts/soak.sh's rss.csv) as a PNG line plot and prints
the summary figures: RSS at the end of the first minute, its range afterwards and the drift.

usage: soak_plot.py RSS.csv OUT.png TITLE

Pillow only (installed with scikit-image by scripts/setup.sh): no plotting library needed.
"""

import csv
import sys

from PIL import Image, ImageDraw, ImageFont


def font(size):
    for path in (
        "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
        "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    ):
        try:
            return ImageFont.truetype(path, size)
        except OSError:
            pass
    return ImageFont.load_default()


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    if len(rows) < 2:
        sys.exit(f"{sys.argv[1]}: fewer than 2 samples")
    t = [float(r["wall_s"]) for r in rows]
    rss = [float(r["rss_mib"]) for r in rows]

    after = [m for s, m in zip(t, rss) if s >= 60.0] or rss
    base = after[0]
    lo, hi = min(after), max(after)
    spread_pct = 100.0 * (hi - lo) / base
    drift_pct = 100.0 * (after[-1] - base) / base
    print(
        f"samples {len(rows)} over {t[-1]:.0f} s; RSS after 1 min {base:.1f} MiB, "
        f"afterwards {lo:.1f}-{hi:.1f} MiB (spread {spread_pct:.1f}% of it), "
        f"end {after[-1]:.1f} MiB (drift {drift_pct:+.1f}%)"
    )

    w, h = 900, 420
    left, right, top, bottom = 80, 40, 50, 50
    img = Image.new("RGB", (w, h), "white")
    d = ImageDraw.Draw(img)
    f, small = font(16), font(12)
    d.text((left, 12), sys.argv[3], fill="black", font=f)
    y_max = max(rss) * 1.15
    y_min = 0.0
    x_max = max(t[-1], 1.0)

    def px(x, y):
        return (
            left + (w - left - right) * x / x_max,
            top + (h - top - bottom) * (1.0 - (y - y_min) / (y_max - y_min)),
        )

    # Axes, grid and labels.
    for i in range(6):
        y = y_min + (y_max - y_min) * i / 5
        a, b = px(0, y), px(x_max, y)
        d.line([a, b], fill=(225, 225, 225))
        d.text((8, a[1] - 7), f"{y:.0f} MiB", fill="black", font=small)
    for i in range(7):
        x = x_max * i / 6
        a = px(x, y_min)
        d.line([a, px(x, y_max)], fill=(235, 235, 235))
        label = f"{x / 60:.0f} min" if x_max >= 300 else f"{x:.0f} s"
        d.text((a[0] - 14, h - bottom + 8), label, fill="black", font=small)
    d.line([px(0, y_min), px(x_max, y_min)], fill="black")
    d.line([px(0, y_min), px(0, y_max)], fill="black")
    # The +-10% band around the first-minute value, then the samples.
    (x0, y0), (x1, y1) = px(60.0, base * 1.1), px(x_max, base * 0.9)
    d.rectangle([x0, y0, x1, y1], fill=(220, 240, 220))
    d.text((px(60.0, base * 1.1)[0] + 4, px(0, base * 1.1)[1] - 16),
           "RSS after 1 min +-10%", fill=(60, 120, 60), font=small)
    d.line([px(x, y) for x, y in zip(t, rss)], fill=(200, 40, 40), width=2)
    img.save(sys.argv[2])


if __name__ == "__main__":
    main()
