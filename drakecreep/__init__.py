"""drakecreep: a ball-screw linear feed drive in Drake.

Parameters -> diagram -> simulate / linearize / sweep -> results -> reports.
SI units everywhere inside the package; mm/s and N/um only at the CLI and in reports.
"""

__version__ = "0.1.0"
