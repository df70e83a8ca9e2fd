"""drakecreep: a ball-screw linear feed drive in Drake.

Parameters -> diagram -> simulate / linearize / sweep / replay -> results -> reports.
SI units everywhere inside the package; mm/s, um and N/um only at the CLI and in reports.

The front door (each name is imported from its subpackage on first use, so ``import drakecreep`` stays light):

>>> import drakecreep as dc
>>> params = dc.preset("paper")                                  # typed, validated parameters
>>> result = dc.simulate(params, dc.Scenario(feed=0.1e-3, load_case=3, duration=2.0))
>>> result.metrics.creep                                          # doctest: +SKIP

============================  ==============================================================
``preset``, ``load_params``,  parameters (:mod:`drakecreep.params`), YAML in and out
``save_params``, ``with_value``
``Scenario``                  feed (m/s), load case, duration (:mod:`drakecreep.scenario`)
``build_diagram``             the Drake diagram (:mod:`drakecreep.model.diagram`)
``lumped``                    the drive as one mass on one spring (:mod:`drakecreep.model.lumped`)
``simulate``                  one run -> ``SimulationResult`` (:mod:`drakecreep.sim.simulation`)
``run_sweep``                 parameter sweeps, serial / processes / Dask (:mod:`drakecreep.sim.sweep`)
``analyze_loops``             linearized velocity and position loops, margins (:mod:`drakecreep.servo.loops`)
``critical_speed``,           the paper's eq. 11 (:mod:`drakecreep.paper.creep`); ``creep_condition(lumped(params,
``creep_condition``           load_case), feed)`` gives C1, zeta, D, D0 and v0 of a drive, as ``drakecreep critical``
``load_measured``             measured runs in any units with their metadata (:mod:`drakecreep.gap.measured`)
``diagnose``                  the sim-to-real gap diagnosis on the Drake replay model, what ``drakecreep
                              diagnose`` runs (:func:`drakecreep.gap.drake_diagnosis.diagnose_drake`)
============================  ==============================================================
"""

import importlib

__version__ = "0.1.0"

#: public name -> module that defines it, or (module, name there)
_API = {
    "preset": "drakecreep.params",
    "load_params": "drakecreep.params",
    "save_params": "drakecreep.params",
    "with_value": "drakecreep.params",
    "DriveParams": "drakecreep.params",
    "Scenario": "drakecreep.scenario",
    "InputError": "drakecreep.errors",
    "build_diagram": "drakecreep.model.diagram",
    "lumped": "drakecreep.model.lumped",
    "simulate": "drakecreep.sim.simulation",
    "SimulationResult": "drakecreep.sim.simulation",
    "run_sweep": "drakecreep.sim.sweep",
    "analyze_loops": "drakecreep.servo.loops",
    "critical_speed": "drakecreep.paper.creep",
    "creep_condition": "drakecreep.paper.creep",
    "load_measured": "drakecreep.gap.measured",
    "diagnose": ("drakecreep.gap.drake_diagnosis", "diagnose_drake"),
}

__all__ = ["__version__", *_API]


def __getattr__(name):
    where = _API.get(name)
    if where is None:
        raise AttributeError(f"module 'drakecreep' has no attribute {name!r}")
    module, attribute = where if isinstance(where, tuple) else (where, name)
    value = getattr(importlib.import_module(module), attribute)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_API))
