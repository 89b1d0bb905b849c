"""The synthetic block measures its truth: interior orientation and catalogue reproduce it."""

from __future__ import annotations

import numpy as np
from conftest import m, um
from synthetic_blocks import block10x4, exact_block

from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.triangulation.block import catalogue_local, interior_orientation
from stereoplotter.triangulation.strip import measurement_rows


def test_interior_orientation_gives_the_collinearity_image_of_the_truth():
    # comparator (film deformation, turn, shift) undone by the fiducials → Eq. (2.53) of the truth
    block, truth = exact_block()
    o = truth.orientations[block.obs_photo]
    expected = object_to_photo(
        truth.points_m[block.obs_point],
        o[:, 3:],
        rotation_matrix(*o[:, :3].T),
        block.camera.focal_length_mm,
    )
    assert np.max(np.abs(interior_orientation(block) - expected)) < 0.01 * um


def test_catalogue_in_sk42_returns_to_the_local_truth():
    block, truth = exact_block()
    where = {p: i for i, p in enumerate(block.point_ids)}
    idx = [where[c.id] for c in block.catalogue]
    assert np.max(np.abs(catalogue_local(block) - truth.points_m[idx])) < 1e-5 * m


def test_layout_every_model_has_points_common_to_three_photos():
    # model connection needs ≥ 2 points on photos k, k+1, k+2 (the nadir column of k+1)
    block, _ = block10x4()
    rows = measurement_rows(block)
    index = {p: j for j, p in enumerate(block.photos)}
    for strip in block.strips:
        j = [index[p] for p in strip]
        for a, b, c in zip(j, j[1:], j[2:], strict=False):
            assert len(set(rows[a]) & set(rows[b]) & set(rows[c])) >= 2


def test_identifiers_are_text():
    block, _ = block10x4()
    assert block.photos[:2] == ("101", "102")
    assert all(isinstance(p, str) for p in block.point_ids)
