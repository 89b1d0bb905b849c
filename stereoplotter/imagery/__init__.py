"""Synthetic photographs and eyepiece views rendered from a scenario's ground truth.

Layer: pure (beside ``setup``). May import ``scenario``, ``geometry``, ``geodesy`` and the base
modules; never ``instrument`` state objects, ``setup``, ``procedure`` or any file loader. Rasters
are numpy arrays; encoding them as PNG is the business of ``io``.
"""
