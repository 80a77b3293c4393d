"""Developer benchmarks and studies of fibril-hpc (run from a source checkout, not installed).

python -m benchmarks.fibril_bench --quick
"""
