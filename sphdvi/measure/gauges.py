"""Run-time gauges of ``<special><gauges>`` (placeholder until the measurement module lands)."""


class RunGauges:
    """Computes the case's gauges during a run at their ``computedt``."""

    def __init__(self, data, params, outdir, resume=False, time=0.0):
        self.items = data["json"]["gauges"]["items"]

    def after_step(self, solver):
        """Called after every time step with the SPH solver."""

    def close(self):
        """Flush the CSV files."""
