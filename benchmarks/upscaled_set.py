"""A copy of a photo folder scaled up to a given size in megapixels, EXIF kept (GPS, focal length in 35 mm, the
sensor-resolution tags scaled with the pixels), for measuring memory at photo sizes no shared set has (issue 33:
<= 4 GiB per stage at 20 MP). The pixels are Lanczos-interpolated, so the detail is the original's: a test of
sizes, not of texture.

    python benchmarks/upscaled_set.py ../shared/data/toledo_2400/images /tmp/mp20/images --mp 20 --count 40
    python benchmarks/memory.py chain --images /tmp/mp20/images --workdir /tmp/mp20/chain

``--turns 0,180,90,270`` repeats the set, each repeat turned by that angle about the optical axis and kept at the
photo's own EXIF position: a camera at the same centre looking the other way, as a return strip over the same
ground sees it (exact where the principal point is the frame's centre), so the repeats join the originals in one
block (pairs with the originals' neighbours have their baseline; a repeat and its original have none). Issue 46
item 3, 40 photos of 3600 x 2700 from seneca_south's 12 at 1800 x 1350:

    python benchmarks/upscaled_set.py ../shared/data/seneca_south/images /tmp/s23/mem40/images --mp 9.72 \
        --turns 0,180,90,270 --count 40
"""
import argparse
import math
import os

from PIL import Image

EXT = (".jpg", ".jpeg", ".tif", ".tiff")
EXIF_IFD, WIDTH, HEIGHT, FP_XRES, FP_YRES = 0x8769, 0xA002, 0xA003, 0xA20E, 0xA20F


TURN = {0: None, 90: Image.Transpose.ROTATE_90, 180: Image.Transpose.ROTATE_180, 270: Image.Transpose.ROTATE_270}


def upscale(src, dst, mp, turn=0):
    im = Image.open(src)
    exif = im.getexif()
    f = math.sqrt(mp * 1e6 / (im.width * im.height))
    size = (int(round(im.width * f)), int(round(im.height * f)))
    sub = exif.get_ifd(EXIF_IFD)
    out = im.convert("RGB").resize(size, Image.LANCZOS)
    if TURN[turn] is not None:
        out = out.transpose(TURN[turn])
    if WIDTH in sub:
        sub[WIDTH], sub[HEIGHT] = out.size
    for tag in (FP_XRES, FP_YRES):
        if tag in sub:
            sub[tag] = float(sub[tag]) * f
    if turn in (90, 270) and FP_XRES in sub and FP_YRES in sub:
        sub[FP_XRES], sub[FP_YRES] = sub[FP_YRES], sub[FP_XRES]
    tmp = os.path.join(os.path.dirname(dst), "." + os.path.basename(dst))
    out.save(tmp, "JPEG", quality=92, exif=exif.tobytes())
    os.replace(tmp, dst)
    return out.size


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("src")
    ap.add_argument("dst")
    ap.add_argument("--mp", type=float, default=20.0, help="megapixels of the copies")
    ap.add_argument("--count", type=int, default=0, help="the first N photos only (of the repeats, in turn order)")
    ap.add_argument("--turns", default="0", help="repeat the set turned by these angles (0, 90, 180, 270)")
    args = ap.parse_args()
    if os.path.abspath(args.src) == os.path.abspath(args.dst):
        raise SystemExit("the copy must go to another folder than the photos")
    turns = [int(t) for t in args.turns.split(",")]
    if any(t not in TURN for t in turns):
        raise SystemExit(f"--turns: each angle must be one of {sorted(TURN)}, not {args.turns}")
    names = sorted(n for n in os.listdir(args.src) if n.lower().endswith(EXT))
    jobs = [(t, n) for t in turns for n in names]
    jobs = jobs[:args.count] if args.count else jobs
    os.makedirs(args.dst, exist_ok=True)
    for t, n in jobs:
        stem, ext = os.path.splitext(n)
        out = os.path.join(args.dst, n if t == 0 else f"{stem}_r{t}{ext}")
        if not os.path.isfile(out):
            w, h = upscale(os.path.join(args.src, n), out, args.mp, t)
            print(f"{os.path.basename(out)}: {w} x {h}", flush=True)


if __name__ == "__main__":
    main()
