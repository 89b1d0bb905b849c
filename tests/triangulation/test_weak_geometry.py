"""Weak geometry is refused by name: the model, the photos and the points at fault."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from synthetic_blocks import block10x4

from stereoplotter.errors import GeometryError
from stereoplotter.triangulation.bundle import bundle_adjust, problem
from stereoplotter.triangulation.strip import strip_block


def _without(block, mask):
    keep = ~mask
    return dataclasses.replace(
        block,
        obs_photo=block.obs_photo[keep],
        obs_point=block.obs_point[keep],
        comparator_mm=block.comparator_mm[keep],
    )


def _photo(block, number):
    return block.photos.index(number)


def test_strip_method_names_the_model_without_its_tie_to_the_strip():
    block, _ = block10x4()
    on = [set(block.obs_point[block.obs_photo == _photo(block, n)]) for n in ("102", "103", "104")]
    triple = sorted(on[0] & on[1] & on[2])
    assert len(triple) == 3  # the standard points of the triple overlap
    mask = (block.obs_photo == _photo(block, "104")) & np.isin(block.obs_point, triple[1:])
    with pytest.raises(GeometryError) as exc:
        strip_block(_without(block, mask))
    text = str(exc.value)
    assert text.startswith("model 103–104: ")
    assert f"also on photo 102 (the tie to the strip): 1 ({block.point_ids[triple[0]]})" in text


def test_bundle_refuses_a_photo_of_two_points_by_its_number():
    block, _ = block10x4()
    mine = np.flatnonzero(block.obs_photo == _photo(block, "205"))
    mask = np.zeros(block.obs_photo.size, bool)
    mask[mine[2:]] = True
    with pytest.raises(GeometryError, match=r"^photo 205 measured 2 points"):
        bundle_adjust(problem(_without(block, mask)))


def test_bundle_non_convergence_names_the_photo_of_worst_condition():
    # photo 205 keeps 3 of its points: determined, but its block is the worst conditioned
    block, _ = block10x4()
    mine = np.flatnonzero(block.obs_photo == _photo(block, "205"))
    mask = np.zeros(block.obs_photo.size, bool)
    mask[mine[3:]] = True
    with pytest.raises(GeometryError, match=r"did not converge.*weakest photos 205 \(condition"):
        bundle_adjust(problem(_without(block, mask)), max_iterations=1)
