"""Parameter studies on Dask: ``python -m rftstatic sweep`` and ``python -m rftstatic fit``.

A study runs one scene many times, each *point* with its own ``--set`` overrides, in Dask worker
processes (a LocalCluster by default, or any scheduler given by address), and keeps every finished
point, so that a killed or repeated study runs only what is missing.

=================  ===========================================================================
module             what it owns
=================  ===========================================================================
``space``          the ``--vary`` / ``--free`` arguments, grids and Latin-hypercube samples
``measures``       MEASURE paths into ``summary.json`` (``probes.tip.z``) and a row's columns
``store``          point keys (resolved scene + code fingerprint), ``results.csv``, ``study.json``
``worker``         what a worker runs for one point (:func:`~rftstatic.study.worker.run_point`)
``runner``         the Dask client (LocalCluster or ``--scheduler``), batches, ``--timeout``, progress
``sweep``          the ``sweep`` command
``fit``            the ``fit`` command: runs and targets, bounded least squares, sensitivities
``identify``       the sensitivity matrix at a fit's optimum: which keys the targets determine
``plots``          each measure against each varied key (a line for one key, a map for two)
=================  ===========================================================================

Dask is imported only when a point has to run: a finished study, ``import rftstatic`` and
``python -m rftstatic case`` never import it.
"""
