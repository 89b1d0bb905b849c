"""Studies over the design space: many configurations × many trials on dask.distributed.

A study (``docs/studies.md``) varies the geometry of the pair, the instrument, the method, the
operator's skill and the instrument's error scale over a grid or a quasi-random sample, runs the
simulated procedure at every configuration (a *cell*) and keeps, per cell, the mean and the Monte
Carlo standard error of each measure: the pass rates of the book's checks, the residual
y-parallax, the height and plan errors, each outcome row's procedure value against its formula at
the same geometry, and (when asked) the one-at-a-time error budget.

* :mod:`~stereoplotter.study.design` — the axes, the cells and the tasks (plain data);
* :mod:`~stereoplotter.study.geometry` — the normal-case scenario of a cell;
* :mod:`~stereoplotter.study.cells` — what one task computes (a chunk of trials, the procedure
  Monte Carlo, the budget) and how a cell's parts combine;
* :mod:`~stereoplotter.study.results` — the xarray Dataset of a study;
* :mod:`~stereoplotter.study.runner` — the tasks run serially or on a Dask cluster.

This layer runs procedures (like ``verification``); it reads no files (the study file is
``io.study_file``, the Zarr store ``io.study_store``).
"""
