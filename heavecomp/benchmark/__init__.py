"""Benchmarks of the toolbox against generated truth: withheld effects, corrupted logs."""
