"""The size of the blocks in which the alignment calls COLMAP (core.align.features.extract_block / match_block):
sized by the work in them, so small frames do not pay a call's fixed cost per image or per pair, and large
photos still report progress (and check a cancel) every few seconds."""
from core.align.features import extract_block, match_block
from core.align.options import (
    EXTRACT_BLOCK,
    EXTRACT_BLOCK_MEGAPIXELS,
    MATCH_BLOCK,
    MATCH_BLOCK_KEYPOINTS,
    MAX_EXTRACT_BLOCK,
    MAX_MATCH_BLOCK,
)


def test_extraction_blocks_follow_sifts_work():
    assert extract_block(1200, 900) == int(EXTRACT_BLOCK_MEGAPIXELS // 1.08)  # toledo: 7 images a call
    # photos over 2 MP are scaled to 2 MP for the features: a 16 MP photo counts as 2 MP, as toledo_2400's do
    assert extract_block(4608, 3456) == extract_block(2400, 1800) == int(EXTRACT_BLOCK_MEGAPIXELS // 2.0)
    # an upsampled image (first octave -1) is four times the work of its pixels
    assert extract_block(480, 360, first_octave=-1) == int(EXTRACT_BLOCK_MEGAPIXELS // (4 * 0.1728))
    assert extract_block(480, 360, first_octave=0) == min(MAX_EXTRACT_BLOCK, int(EXTRACT_BLOCK_MEGAPIXELS // 0.1728))
    assert extract_block(48, 36) == MAX_EXTRACT_BLOCK  # bounded above
    assert extract_block(8000, 6000, max_image_size=8000) == EXTRACT_BLOCK  # and below


def test_matching_blocks_follow_the_keypoints():
    assert match_block(MATCH_BLOCK_KEYPOINTS) == MATCH_BLOCK
    assert match_block(MATCH_BLOCK_KEYPOINTS / 2) == 4 * MATCH_BLOCK  # a pair costs the product of the counts
    assert match_block(3 * MATCH_BLOCK_KEYPOINTS) == MATCH_BLOCK  # never below the reference
    assert match_block(10) == MAX_MATCH_BLOCK  # bounded above
    assert match_block(0) == MAX_MATCH_BLOCK  # an empty database does not divide by zero
