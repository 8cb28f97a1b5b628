"""Multispectral metadata (issue 37): everything core/io/multispectral.py reads from each band file of a folder,
the captures it finds, the block's warnings (or the error that stops it) and the primary band.

usage: python benchmarks/multispectral_metadata.py [FOLDER] [--tolerance S]
       (FOLDER: ../shared/data/sequoia_sample by default: one Parrot Sequoia capture, GRE / RED / REG / NIR 16-bit
       TIFFs 1280 x 960 and an RGB JPG 4608 x 3456)
"""
from __future__ import annotations

import argparse
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from core.io.multispectral import (  # noqa: E402
    DEFAULT_TIME_TOLERANCE_S,
    Block,
    MultispectralError,
    band_files,
    check_captures,
    group_captures,
    primary_band,
    read_band_info,
)

DEFAULT_FOLDER = os.path.join(ROOT, "..", "shared", "data", "sequoia_sample")


def _fmt(value) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, tuple) and len(value) > 6:
        return "(" + ", ".join(_fmt(v) for v in value[:6]) + f", ... {len(value)} values)"
    if isinstance(value, tuple):
        return "(" + ", ".join(_fmt(v) for v in value) + ")"
    return str(value)


def print_info(info) -> None:
    print(f"\n== {info.name}  {info.width} x {info.height}")
    for key in ("band_name", "band_names", "central_wavelength_nm", "fwhm_nm", "rig_name", "rig_camera_index",
                "rig_relatives", "capture_id", "timestamp", "make", "model", "black_level", "band_gain",
                "gain_adjustment", "exposure_s", "iso", "line_readout_time", "sensor_temperature_c"):
        print(f"  {key:22s} {_fmt(getattr(info, key))}")
    lens = info.lens
    print("  lens                  " + ", ".join(f"{k}={_fmt(v)}" for k, v in vars(lens).items() if v is not None))
    v = info.vignetting
    print("  vignetting            " + (f"{v.model} from {v.source}: {_fmt(v.coefficients)}"
                                        + (f", exponents {_fmt(v.exponents)}" if v.exponents else "")
                                        + (f", centre {_fmt(v.center_px)} px" if v.center_px else "")
                                        if v else "None"))
    ir = info.irradiance
    if ir is None:
        print("  irradiance            None")
        return
    print(f"  irradiance            from {ir.source}: value={_fmt(ir.value)} horizontal={_fmt(ir.horizontal)} "
          f"scale_to_si={_fmt(ir.scale_to_si)} records={len(ir.records)}")
    for rec in ir.records[:2]:
        print(f"    record              {rec}")
    if len(ir.records) > 2:
        last = ir.records[-1]
        print(f"    ... last            t={last.timestamp_us} us ch0={last.ch0} ch1={last.ch1} "
              f"(records span {(last.timestamp_us - ir.records[0].timestamp_us) / 1e6:.3f} s)")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", nargs="?", default=DEFAULT_FOLDER)
    ap.add_argument("--tolerance", type=float, default=DEFAULT_TIME_TOLERANCE_S,
                    help="seconds within which a file without capture id joins a capture")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    infos = [read_band_info(p) for p in band_files(args.folder)]
    t_read = time.perf_counter() - t0
    for info in infos:
        print_info(info)
    captures = group_captures(infos, args.tolerance)
    print(f"\n== captures ({len(captures)}; tolerance {args.tolerance} s)")
    for cap in captures:
        print(f"  {cap.capture_id}  {cap.timestamp}  rig {cap.rig_name}")
        for b in cap.bands:
            dt = (b.timestamp - cap.timestamp).total_seconds() * 1e3 if b.timestamp and cap.timestamp else None
            print(f"    {b.band_name:10s} {b.name}  +{_fmt(dt)} ms  id {b.capture_id}")
    try:
        warnings = check_captures(infos, captures, args.tolerance)
    except MultispectralError as e:
        print(f"\n== error\n{e}")
        return 1
    print("\n== warnings\n" + ("\n".join(f"  {w}" for w in warnings) if warnings else "  none"))
    t1 = time.perf_counter()
    block = Block(tuple(captures), tuple(), tuple(warnings))
    primary = primary_band(block)
    print(f"\n== primary band: {primary.name} ({primary.reason})"
          + (f"; scores {primary.scores}" if primary.scores else ""))
    no_rgb = Block(tuple(type(c)(c.capture_id, c.rig_name, c.timestamp, tuple(b for b in c.bands if not b.is_rgb))
                         for c in captures), tuple(), tuple())
    if any(b.is_rgb for c in captures for b in c.bands):
        alt = primary_band(no_rgb)
        print(f"   without the RGB frame: {alt.name} ({alt.reason}); scores "
              + ", ".join(f"{k} {v:.4g}" for k, v in alt.scores.items()))
    print(f"\nread {len(infos)} files in {t_read:.2f} s; primary band in {time.perf_counter() - t1:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
