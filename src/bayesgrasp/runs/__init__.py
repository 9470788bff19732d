"""Runs: what a request asks of the library, shared by every surface.

The command line, the web service and sweeps each parse their own input (options, JSON
bodies, sweep settings) into the same values and then call the same code:

- :mod:`.specs`: the part to read (:class:`~.specs.PartSpec`), the problem and planner
  (:class:`~.specs.ProblemSpec`), a sensing policy's options (:class:`~.specs.SenseSpec`),
  the guaranteed plan (:func:`~.specs.guaranteed_plan`) and the provenance a run writes
  (:func:`~.specs.run_inputs`, :func:`~.specs.simulate_inputs`);
- :mod:`.noisy`: the noise-aware plans of a problem and their document
  (:class:`~.noisy.NoisyRun`).

Nothing here reads command-line text or prints; bad values raise a
:class:`~bayesgrasp.errors.BayesGraspError`, which each surface reports its own way.
"""
