#!/usr/bin/python3
"""The headset's camera (HMD_CAMERA, image_t) into OpenCV: each frame decoded to BGR (JPEG by cv2.imdecode,
raw formats by row stride), its edges found (cv2.Canny), both written to a folder (--show: a window).

    PYTHONPATH=python scripts/orbed join /usr/bin/python3 examples/hmd_camera_opencv.py --frames 30
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import cv2  # noqa: E402
import numpy as np  # noqa: E402

from orbed import bus, types  # noqa: E402

image_t = types.lcm_types().image_t


def to_bgr(m):
    """The frame as an H x W x 3 BGR array."""
    if m.pixel_format == image_t.FORMAT_JPEG:
        return cv2.imdecode(np.frombuffer(m.data, np.uint8), cv2.IMREAD_COLOR)
    channels = 1 if m.pixel_format == image_t.FORMAT_GRAY8 else 3
    rows = np.frombuffer(m.data, np.uint8).reshape(m.height, m.row_stride)
    pixels = rows[:, :m.width * channels].reshape(m.height, m.width, channels)
    convert = {image_t.FORMAT_GRAY8: cv2.COLOR_GRAY2BGR, image_t.FORMAT_RGB8: cv2.COLOR_RGB2BGR}
    return cv2.cvtColor(pixels, convert[m.pixel_format]) if m.pixel_format in convert else pixels.copy()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=30, help="stop after this many frames")
    parser.add_argument("--out", default="hmd_frames", help="folder for frame_<n>.png and edges_<n>.png")
    parser.add_argument("--show", action="store_true", help="show the frames in a window instead")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    seen = []

    def on_frame(channel, m):
        bgr = to_bgr(m)
        edges = cv2.Canny(cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY), 50, 150)
        print(f"frame {len(seen)}: {bgr.shape[1]}x{bgr.shape[0]}, {np.count_nonzero(edges)} edges", flush=True)
        if args.show:
            cv2.imshow(channel, bgr)
            cv2.waitKey(1)
        else:
            cv2.imwrite(os.path.join(args.out, f"frame_{len(seen)}.png"), bgr)
            cv2.imwrite(os.path.join(args.out, f"edges_{len(seen)}.png"), edges)
        seen.append(m.utime)

    b = bus.Bus()
    b.subscribe("HMD_CAMERA", image_t, on_frame)
    if not b.handle_until(lambda: len(seen) >= args.frames, timeout_s=120):
        sys.exit(f"only {len(seen)} frames in 120 s")


if __name__ == "__main__":
    main()
