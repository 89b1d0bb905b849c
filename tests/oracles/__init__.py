"""Independent reference computations (oracles) used by the tests and benchmarks."""
