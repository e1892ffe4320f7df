#!/usr/bin/env python3
"""Writes scikit-image's public-domain test photos as PNG: test_photos.py OUT_DIR NAME..."""
import os
import sys

try:
    import skimage.data
    import skimage.io
except ImportError as e:
    sys.exit(f"test_photos.py needs scikit-image: pip install scikit-image ({e})")

out = sys.argv[1]
os.makedirs(out, exist_ok=True)
for name in sys.argv[2:]:
    image = getattr(skimage.data, name)()
    skimage.io.imsave(os.path.join(out, f"{name}.png"), image, check_contrast=False)
