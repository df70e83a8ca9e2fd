"""The seed paper's rigid-flexible feed system as a Drake ``MultibodyPlant`` and its modal analysis.

A sibling of :mod:`drakecreep.model` (it may import the base modules and ``model``): the same
parameters, the bodies of the paper's Fig. 1 and the joints of its Tables 1-2 and 4-6. See
``docs/multibody.md``.
"""

from drakecreep.multibody.modes import ModalResult, Mode, modal_analysis, not_in_multibody, two_mass_axial_frequency
from drakecreep.multibody.plant import MultibodyDrive, build_multibody
from drakecreep.multibody.rig import RigGeometry, paper_joints

__all__ = ["build_multibody", "MultibodyDrive", "modal_analysis", "ModalResult", "Mode",
           "two_mass_axial_frequency", "not_in_multibody", "RigGeometry", "paper_joints"]
