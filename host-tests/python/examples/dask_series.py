"""A test series over many recordings on Dask: `impact.analyze` mapped over the files on
Dask's workers, the series' statistics gathered with `impact.statistics` (the tool's own
computation: the same numbers as `impact analyze FILES… --json`).

    python host-tests/python/examples/dask_series.py host-tests/data/pyfrf-impact-hammer/*.csv

Here Dask runs the analyses in local worker processes. On a cluster, start a scheduler and
workers where the recordings are readable (a shared file system or object store mounted at
the same path; `pip install ./host-tests/python` on every worker) and connect first:

    from dask.distributed import Client
    client = Client("tcp://scheduler:8786")   # then the same code: compute() uses it
"""

import sys

import dask.bag as db

import impact


def series_statistics(files, scheduler="processes", **options):
    """Every recording analysed on Dask (one task each), gathered in the files' order, and
    the series' statistics over them."""
    bag = db.from_sequence([str(f) for f in files], npartitions=max(1, len(files)))
    analyses = bag.map(lambda f: impact.analyze(f, **options)).compute(scheduler=scheduler)
    return analyses, impact.statistics(analyses)


if __name__ == "__main__":
    analyses, stats = series_statistics(sys.argv[1:], units="n", mass=1.0)
    for f, a in zip(sys.argv[1:], analyses):
        print(f"{f}: {len(a.impacts)} impacts")
    print(stats.table[["n", "mean", "sd", "cv", "min", "max"]])
