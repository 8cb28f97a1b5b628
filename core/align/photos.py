"""The photos an alignment was made from, and the check every later stage that reads photos makes.

The align stage records a content fingerprint of every photo it aligned (:func:`core.io.images.photo_fingerprint`:
size + a hash of three blocks) in its manifest record under ``photo_fingerprints``.  The DSM and orthophoto
stages read the photos again (pixels for matching and for the mosaic) and call :func:`check_photos` first: a
photo that is missing, unreadable or other than the one aligned (another photo under the same name, an edited
one) is refused with an :class:`~core.io.images.ImageError` that names the photos and says to re-run Align.
Refusing, not marking the stages stale: the model's poses belong to the aligned photos, so a product from
another photo is wrong however often it is rebuilt; only a new alignment (or the original photos) mends it.

A workspace aligned before the fingerprints were recorded has none: its photos are checked for readability
(:func:`core.io.images.check_image`) and the stage notes in the log that they cannot be compared.
"""
from __future__ import annotations

import os
from typing import Dict, List, Mapping, Sequence

from ..io.images import ImageError, ImageInfo, check_image, photo_fingerprint
from ..project.layout import Layout
from ..project.stages import ALIGN
from ..project.workspace import Workspace
from .options import AlignError

PHOTO_FINGERPRINTS = "photo_fingerprints"  # key of the align stage's record: {image name: fingerprint}


def fingerprint_photos(infos: Sequence[ImageInfo]) -> Dict[str, str]:
    """{image name: content fingerprint} of the photos being aligned (ImageError naming an unreadable one)."""
    out: Dict[str, str] = {}
    for im in infos:
        try:
            out[im.name] = photo_fingerprint(im.path)
        except OSError as e:
            raise ImageError(f"{im.path}: cannot be read ({e.strerror or e})") from e
    return out


def _list(names: Sequence[str], limit: int = 8) -> str:
    return ", ".join(names[:limit]) + (f" and {len(names) - limit} more" if len(names) > limit else "")


def check_same_photos(ws: Workspace, images_dir: str, fingerprints: Dict[str, str]) -> None:
    """AlignError when ``ws`` holds a finished alignment of the photos of another folder and ``images_dir`` holds
    none of them (by content fingerprint; by name in a workspace aligned before fingerprints were recorded): an
    alignment there would replace the block's and leave its later products stale without a word.  The
    workspace's own folder (whatever it holds now) and the same photos moved elsewhere are a re-alignment."""
    lay = Layout(ws)
    recorded_dir = ws.data.get("images_dir")
    if not recorded_dir or not lay.has_aligned_model():
        return
    if os.path.normcase(os.path.abspath(recorded_dir)) == os.path.normcase(os.path.abspath(images_dir)):
        return
    recorded = ws.stage(ALIGN).get(PHOTO_FINGERPRINTS)
    if isinstance(recorded, dict) and recorded:
        n_old, common = len(recorded), set(recorded.values()) & set(fingerprints.values())
    else:
        names = {im.get("name") for im in ws.data.get("images", []) if isinstance(im, dict)}
        n_old, common = len(names), names & set(fingerprints)
    if common or not n_old:
        return
    later = [k for k, v in ws.data.get("stages", {}).items() if k != ALIGN and (v or {}).get("status") == "done"]
    products = f" and leave what was made from it ({', '.join(later)}) stale" if later else ""
    raise AlignError(
        f"workspace {ws.root} was aligned from the photos of {recorded_dir} ({n_old} photos); {images_dir} holds "
        f"none of them ({len(fingerprints)} other photos): aligning them here would replace the workspace's "
        f"alignment{products}. To re-align this workspace's photos, give IMAGES={recorded_dir}; to align the "
        f"photos of {images_dir}, give a new WORKSPACE (a folder of its own)")


def check_photos(ws: Workspace, photos: Mapping[str, str]) -> List[str]:
    """Check the photos {image name: path} a stage is about to read against the alignment's fingerprints.

    Returns notes for the log (an old workspace without fingerprints); raises ImageError naming the missing,
    unreadable or changed photos."""
    recorded = ws.stage(ALIGN).get(PHOTO_FINGERPRINTS)
    missing = sorted(n for n, p in photos.items() if not os.path.isfile(p))
    if missing:
        folder = os.path.dirname(photos[missing[0]]) or "."
        if not os.path.isdir(folder):  # the whole folder moved or renamed after the alignment
            raise ImageError(f"the photos' folder {folder} no longer exists ({len(missing)} photo(s) of the aligned "
                             f"model were read from it: {_list(missing)}): the photos were moved or the folder "
                             "renamed after 'Align images'; put the folder back, or re-run 'Align images' on the "
                             "photos where they are now")
        raise ImageError(f"{len(missing)} photo(s) of the aligned model are missing from {folder}: {_list(missing)}; "
                         "put them back or re-run 'Align images' on the photos as they are now")
    if not isinstance(recorded, dict):
        for n in sorted(photos):
            check_image(photos[n])
        return [f"the alignment of {ws.root} recorded no photo fingerprints (an older workspace): the {len(photos)} "
                "photos were checked for readability but cannot be compared with the photos aligned; re-run "
                "'Align images' to record them"]
    changed = []
    for n in sorted(photos):
        try:
            fp = photo_fingerprint(photos[n])
        except OSError as e:
            raise ImageError(f"{photos[n]}: cannot be read ({e.strerror or e})") from e
        if n in recorded and recorded[n] != fp:
            changed.append(n)
    if changed:
        folder = os.path.dirname(photos[changed[0]]) or "."
        raise ImageError(
            f"{len(changed)} photo(s) in {folder} changed since the alignment (other content under the same name): "
            f"{_list(changed)}. The model's camera poses belong to the photos that were aligned, so products from "
            "these would be wrong: re-run 'Align images' (and 'Georeference') or put the original photos back")
    return []
