"""A copy of a photo folder scaled up to a given size in megapixels, EXIF kept (GPS, focal length in 35 mm, the
sensor-resolution tags scaled with the pixels), for measuring memory at photo sizes no shared set has (issue 33:
<= 4 GiB per stage at 20 MP). The pixels are Lanczos-interpolated, so the detail is the original's: a test of
sizes, not of texture.

    python benchmarks/upscaled_set.py ../shared/data/toledo_2400/images /tmp/mp20/images --mp 20 --count 40
    python benchmarks/memory.py chain --images /tmp/mp20/images --workdir /tmp/mp20/chain
"""
import argparse
import math
import os

from PIL import Image

EXT = (".jpg", ".jpeg", ".tif", ".tiff")
EXIF_IFD, WIDTH, HEIGHT, FP_XRES, FP_YRES = 0x8769, 0xA002, 0xA003, 0xA20E, 0xA20F


def upscale(src, dst, mp):
    im = Image.open(src)
    exif = im.getexif()
    f = math.sqrt(mp * 1e6 / (im.width * im.height))
    size = (int(round(im.width * f)), int(round(im.height * f)))
    sub = exif.get_ifd(EXIF_IFD)
    if WIDTH in sub:
        sub[WIDTH], sub[HEIGHT] = size
    for tag in (FP_XRES, FP_YRES):
        if tag in sub:
            sub[tag] = float(sub[tag]) * f
    tmp = os.path.join(os.path.dirname(dst), "." + os.path.basename(dst))
    im.convert("RGB").resize(size, Image.LANCZOS).save(tmp, "JPEG", quality=92, exif=exif.tobytes())
    os.replace(tmp, dst)
    return size


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("src")
    ap.add_argument("dst")
    ap.add_argument("--mp", type=float, default=20.0, help="megapixels of the copies")
    ap.add_argument("--count", type=int, default=0, help="the first N photos only")
    args = ap.parse_args()
    if os.path.abspath(args.src) == os.path.abspath(args.dst):
        raise SystemExit("the copy must go to another folder than the photos")
    names = sorted(n for n in os.listdir(args.src) if n.lower().endswith(EXT))
    names = names[:args.count] if args.count else names
    os.makedirs(args.dst, exist_ok=True)
    for n in names:
        out = os.path.join(args.dst, n)
        if not os.path.isfile(out):
            w, h = upscale(os.path.join(args.src, n), out, args.mp)
            print(f"{n}: {w} x {h}", flush=True)


if __name__ == "__main__":
    main()
