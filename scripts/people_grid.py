"""A grid of the people in a `rover dataset` folder, for docs/GROUND_TRUTH.md.

Reads the dataset's ground-truth records (ground_truth/{train,val}/*.json), takes the first
COUNT people seen whole (not truncated, visibility >= 0.9, not an ignore region) in image-number
order, crops each around its full box (padded, 1:2 width to height) and pastes the crops into a
grid. Uses Pillow (in the tests' venv: scripts/setup.sh test).

    python scripts/people_grid.py DATASET OUT.png [--count 16] [--columns 8]
"""

import argparse
import json
import pathlib

from PIL import Image


def people(dataset: pathlib.Path):
    records = sorted(
        dataset.glob("ground_truth/*/*.json"),
        key=lambda p: json.loads(p.read_text())["index"],
    )
    for path in records:
        record = json.loads(path.read_text())
        image = dataset / "images" / record["split"] / record["file_name"]
        for thing in record["objects"]:
            if (
                thing["class"] == "person"
                and not thing["ignore"]
                and not thing["truncated"]
                and thing["visibility"] >= 0.9
            ):
                yield image, thing["full_bbox"]


def crop(image: pathlib.Path, bbox, size):
    x, y, w, h = bbox
    cx, cy = x + w / 2, y + h / 2
    half_h = h * 1.15 / 2
    half_w = max(w * 1.15 / 2, half_h / 2)
    half_h = max(half_h, 2 * half_w)
    with Image.open(image) as im:
        box = (cx - half_w, cy - half_h, cx + half_w, cy + half_h)
        return im.convert("RGB").crop(tuple(round(v) for v in box)).resize(size)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset", type=pathlib.Path)
    parser.add_argument("out", type=pathlib.Path)
    parser.add_argument("--count", type=int, default=16)
    parser.add_argument("--columns", type=int, default=8)
    args = parser.parse_args()
    size = (120, 240)
    found = list(people(args.dataset))[: args.count]
    if len(found) < args.count:
        raise SystemExit(f"{args.dataset}: only {len(found)} people seen whole")
    rows = (len(found) + args.columns - 1) // args.columns
    grid = Image.new("RGB", (size[0] * args.columns, size[1] * rows), "white")
    for k, (image, bbox) in enumerate(found):
        grid.paste(crop(image, bbox, size), ((k % args.columns) * size[0], (k // args.columns) * size[1]))
    grid.save(args.out)
    print(f"{args.out}: {len(found)} people from {args.dataset}")


if __name__ == "__main__":
    main()
