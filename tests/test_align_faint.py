"""Alignment on real faint farmland (issue 46 item 2, docs/notes_issue46_align.md): why a block splits.

seneca_south's 12 photos (a fixed-wing strip at ~67 m over bare fields, 52-74 % forward overlap, frames tilted up
to 15 deg) verify pairs between neighbours but, two photos apart, on the bare field, often none: the incremental
mapping has no point seen by three photos there and splits the strip.  The verified pairs below (>= 15 inliers) are
those of the first pass's features on the real photos; the diagnosis must name that, not "too few matches"."""
import glob
import os

from core.align.diagnosis import component_link, diagnose_unregistered
from core.io.images import ImageInfo
from tests.conftest import shared

# IMG_04xx pairs with >= 15 verified inliers at the fast path's features (1632 px, 4096, octave 0), from the note
SENECA_LINKS = [("0446", "0447"), ("0446", "0448"), ("0447", "0448"), ("0448", "0449"), ("0448", "0450"),
                ("0449", "0450"), ("0449", "0451"), ("0449", "0457"), ("0450", "0451"), ("0450", "0457"),
                ("0451", "0452"), ("0451", "0453"), ("0451", "0454"), ("0451", "0457"), ("0452", "0453"),
                ("0452", "0454"), ("0452", "0456"), ("0453", "0454"), ("0453", "0456"), ("0454", "0455"),
                ("0454", "0456"), ("0455", "0456")]
MAIN = {"0451", "0452", "0453", "0454", "0456"}  # the fast path's main block


def _info(name):
    return ImageInfo(name=name, path=f"/x/{name}", width=1800, height=1350, bands=3, dtype="Byte")


def test_a_component_met_only_in_pairs_is_named_so():
    chain = [("a", "b"), ("b", "c"), ("c", "d"), ("d", "e"), ("e", "f")]  # no photo matches the one after next
    why = component_link(["a", "b", "c"], {"d", "e", "f"}, chain)
    assert "only in pairs (1 verified: c-d)" in why and "three photos" in why
    assert "no verified pair" in component_link(["a", "b"], {"e", "f"}, chain)


def test_seneca_components_are_diagnosed_by_how_they_meet_the_block():
    infos = [_info(f"{k:04d}") for k in range(446, 458)]
    others = [["0448", "0449", "0450", "0457"], ["0446", "0447"]]
    partners = {i.name: sum(1 for p in SENECA_LINKS if i.name in p) for i in infos}
    why = diagnose_unregistered(infos, MAIN, others, partners, links=SENECA_LINKS)
    # the strip meets the block at 0451 only: through the triple 0450-0457-0451 (21-64 inliers), too few points
    assert "photo triples (0449, 0451, 0450)" in why["0450"] and "too few points" in why["0450"]
    assert "shares no verified pair with the main block" in why["0446"]
    assert "too few matches" not in " ".join(why.values())
    # without the verified pairs the old wording stays
    assert "shares too few matches" in diagnose_unregistered(infos, MAIN, others, partners)["0450"]


def test_seneca_photos_are_the_ones_measured():
    photos = sorted(glob.glob(os.path.join(shared("seneca_south", "images"), "*.jpg")))  # skips when absent
    assert [os.path.basename(p)[4:8] for p in photos] == [f"{k:04d}" for k in range(446, 458)]
