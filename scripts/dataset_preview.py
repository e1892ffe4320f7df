#!/usr/bin/env python3
"""Draws a `rover dataset` folder's labels over its images, to check them by eye.

    python3 scripts/dataset_preview.py DATASET OUT.png [IMAGE ...]

IMAGE is an image number (12 or 000012); without any, the first four. Green: the box trainers
get (the visible, tight box: YOLO label and COCO bbox) with the class and visibility; orange:
the full (amodal) box where it differs; grey: ignore regions (COCO iscrowd, no YOLO line).
Tiles of 2 across, at the camera's size. Needs Pillow (in the tests' environment).
"""
import argparse
import glob
import json
import os

from PIL import Image, ImageDraw

GREEN, ORANGE, GREY = (0, 255, 0), (255, 200, 0), (150, 150, 150)


def record(root, number):
    found = glob.glob(os.path.join(root, "ground_truth", "*", f"{int(number):06d}.json"))
    if not found:
        raise SystemExit(f"{root}: no record of image {number} (ground_truth/*/{int(number):06d}.json)")
    with open(found[0]) as f:
        return json.load(f)


def tile(root, r):
    image = Image.open(os.path.join(root, "images", r["split"], r["file_name"])).convert("RGB")
    d = ImageDraw.Draw(image)
    for o in r["objects"]:
        x, y, w, h = o["bbox"]
        if o["ignore"]:
            d.rectangle([x, y, x + w, y + h], outline=GREY, width=2)
            d.text((x + 2, y + 2), "ignore", fill=GREY)
            continue
        fx, fy, fw, fh = o["full_bbox"]
        if abs(fw - w) > 1 or abs(fh - h) > 1:
            d.rectangle([fx, fy, fx + fw, fy + fh], outline=ORANGE, width=1)
        d.rectangle([x, y, x + w, y + h], outline=GREEN, width=2)
        label = f"{o['class']} {o['visibility']:.2f}"
        top = max(0, y - 12)
        d.rectangle([x, top, x + 6 * len(label) + 2, top + 12], fill=(0, 0, 0))
        d.text((x + 1, top), label, fill=GREEN)
    d.text((6, 6), f"{r['split']}/{r['file_name']}", fill=(255, 255, 255))
    return image


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dataset", help="a folder rover dataset wrote")
    p.add_argument("out", help="the PNG to write")
    p.add_argument("images", nargs="*", help="image numbers (default: the first four)")
    a = p.parse_args()
    numbers = a.images or ["0", "1", "2", "3"]
    tiles = [tile(a.dataset, record(a.dataset, n)) for n in numbers]
    w, h = tiles[0].size
    sheet = Image.new("RGB", (w * min(2, len(tiles)), h * ((len(tiles) + 1) // 2)))
    for i, t in enumerate(tiles):
        sheet.paste(t, ((i % 2) * w, (i // 2) * h))
    sheet.quantize(256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(a.out, optimize=True)
    print(f"wrote {a.out}: {len(tiles)} images")


if __name__ == "__main__":
    main()
