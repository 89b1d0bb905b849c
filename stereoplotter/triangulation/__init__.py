"""Analytic phototriangulation upstream of the setup sheet.

A *block* (:mod:`~stereoplotter.triangulation.block`) holds what a triangulation office has: the
camera certificate, the photo numbers by strip, comparator measurements of fiducials and of tie,
pass and control points, the control catalogue in SK-42 and the a priori σ. From it the exterior
orientation of every photo is found by the bundle block adjustment
(:mod:`~stereoplotter.triangulation.bundle`), by strip triangulation (dependent or independent
models, :mod:`~stereoplotter.triangulation.strip`, with the 7-parameter absolute orientation of
:mod:`~stereoplotter.triangulation.absolute` and the polynomial removal of strip deformation of
:mod:`~stereoplotter.triangulation.polynomial`) or by the polygon method. Pure numerics: numpy,
scipy and the geometry and geodesy layers; no files.
"""
