#!/usr/bin/env python3
"""Checks that `fictus plot` made non-trivial PNG files. Usage: check_plots.py DIR NAME..."""
import os
import sys

import matplotlib.image as mpimg
import numpy as np


def main(folder, names):
    for name in names:
        path = os.path.join(folder, name)
        assert os.path.exists(path), f"{path} missing"
        assert os.path.getsize(path) > 10000, f"{path} is only {os.path.getsize(path)} bytes"
        image = mpimg.imread(path)
        assert image.shape[0] > 300 and image.shape[1] > 300, image.shape
        assert np.std(image[..., :3]) > 0.05, f"{path} is nearly blank"
        colours = len(np.unique((image[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0))
        assert colours > 50, f"{path} has only {colours} colours"
    print("plots OK: " + ", ".join(names))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
