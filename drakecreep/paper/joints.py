"""Fixed-joint stiffness and damping by Yoshimura's integral (seed paper Section 3.1, Tables 1-2).

Yoshimura's method: measure the dynamic properties of a *unit area* of a joint surface as functions
of the contact pressure ``p`` (typically power laws ``k = α p^β``), then integrate over the real face
with its pressure distribution: ``K = ∫_A k(p(x, y)) dA`` (same for damping and the tangential
direction). Source of the method: M. Yoshimura, "Computer-aided design improvement of machine tool
structure incorporating joint dynamics data", Annals of the CIRP 28(1):241-246, 1979.

What this module does *not* ship: verified unit-area coefficients. Yoshimura's measured tables
(and the paper's, which it does not print) were not available to this project, so no coefficient set
here is presented as published data. :data:`EXAMPLE_GROUND_STEEL` is an explicitly *illustrative* set:
the exponent 0.5 follows the classical contact-deformation law ``δ = c p^0.5`` for ground joints
(Levina & Reshetov, *Contact stiffness of machines*), the level is an assumption, and its damping and
tangential ratios are the ones the paper's Table 1 implies (see :func:`table1_ratios`). Supply your
own :class:`UnitAreaJoint` for real work.

Pressure distributions provided: uniform over a face, a bolt "pressure cone" (each bolt's preload
spread over the annulus under the head out to the frustum radius, uniformly or falling linearly with
radius; 30° frustum half-angle as in Shigley's *Mechanical Engineering Design*), and the Lamé
thick-cylinder pressure of an interference fit.

SI units: pressure Pa, unit-area stiffness N/m³ (= Pa/m), unit-area damping N s/m³.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

from drakecreep.errors import InputError

__all__ = [
    "PowerLaw",
    "UnitAreaJoint",
    "EXAMPLE_GROUND_STEEL",
    "JointDynamics",
    "yoshimura_integral",
    "BoltedFace",
    "bolted_joint",
    "InterferenceFit",
    "lame_interference_pressure",
    "interference_fit_joint",
    "table1_ratios",
    "table2_ratios",
    "AXIAL_PATH_JOINTS",
    "axial_path_joints",
]


@dataclass(frozen=True)
class PowerLaw:
    """Unit-area property ``value = coefficient * (p / reference_pressure) ** exponent``.

    Attributes
    ----------
    coefficient : float
        Value at the reference pressure (N/m³ for stiffness, N s/m³ for damping).
    exponent : float
        Pressure exponent ``β`` (``0 < β <= 1`` for real joints).
    reference_pressure : float
        Pa; 1 MPa by default so the coefficient reads as "the value at 1 MPa".
    """

    coefficient: float
    exponent: float
    reference_pressure: float = 1e6

    def __call__(self, p):
        """Evaluate at contact pressure(s) ``p`` (Pa); zero where ``p <= 0`` (no contact)."""
        p = np.asarray(p, dtype=float)
        ratio = np.clip(p, 0.0, None) / self.reference_pressure
        out = np.where(p > 0.0, self.coefficient * ratio**self.exponent, 0.0)
        return out[()] if out.ndim == 0 else out


@dataclass(frozen=True)
class UnitAreaJoint:
    """Unit-area normal/tangential stiffness and damping of a joint surface vs contact pressure.

    Attributes
    ----------
    kn, cn, kt, ct : PowerLaw
        Normal stiffness, normal damping, tangential stiffness, tangential damping per unit area.
    source : str
        Where the numbers come from (keep it honest).
    """

    kn: PowerLaw
    cn: PowerLaw
    kt: PowerLaw
    ct: PowerLaw
    source: str


#: Illustrative ground steel-on-steel/cast-iron joint, NOT published data (see module docstring):
#: kn = 5e12 N/m³ at 1 MPa with exponent 0.5 (assumed level; exponent from δ = c p^0.5); cn, kt, ct
#: from the constant ratios of the paper's Table 1 (cn/kn = 1.737e-6 s, kt/kn = 1.748e-4,
#: ct/kn = 6.74e-6 s, all at the same pressure exponent as kn).
EXAMPLE_GROUND_STEEL = UnitAreaJoint(
    kn=PowerLaw(5e12, 0.5),
    cn=PowerLaw(5e12 * 1.737e-6, 0.5),
    kt=PowerLaw(5e12 * 1.748e-4, 0.5),
    ct=PowerLaw(5e12 * 6.74e-6, 0.5),
    source="illustrative: level assumed, exponent 0.5 (Levina-Reshetov), ratios from paper Table 1",
)


@dataclass(frozen=True)
class JointDynamics:
    """Integrated joint properties.

    Attributes
    ----------
    kn, cn, kt, ct : float
        Normal stiffness (N/m), normal damping (N s/m), tangential stiffness, tangential damping.
    contact_area : float
        Area carrying pressure, m².
    mean_pressure : float
        Load / contact area, Pa.
    """

    kn: float
    cn: float
    kt: float
    ct: float
    contact_area: float
    mean_pressure: float


def yoshimura_integral(law, pressure, area_weights):
    """Yoshimura's integral on a discretised face: ``Σ law(p_i) dA_i``.

    Parameters
    ----------
    law : callable
        Unit-area property ``f(p)`` (e.g. a :class:`PowerLaw`).
    pressure : array_like
        Contact pressure at each face element, Pa.
    area_weights : array_like
        Area of each element, m² (same shape as ``pressure``).

    Returns
    -------
    float
        Integrated property (unit-area units × m²).
    """
    p = np.asarray(pressure, dtype=float)
    w = np.asarray(area_weights, dtype=float)
    if p.shape != w.shape:
        raise InputError("area_weights", w.shape, f"same shape as pressure {p.shape}")
    return float(np.sum(np.asarray(law(p), dtype=float) * w))


def _integrate_all(unit: UnitAreaJoint, integrate) -> tuple[float, float, float, float]:
    return tuple(integrate(law) for law in (unit.kn, unit.cn, unit.kt, unit.ct))


@dataclass(frozen=True)
class BoltedFace:
    """A flat joint face clamped by bolts.

    Attributes
    ----------
    area : float
        Nominal face area, m².
    bolts : int
        Number of bolts.
    preload : float
        Preload per bolt, N.
    head_radius : float
        Radius of the bolt head / washer bearing face, m.
    hole_radius : float
        Radius of the clearance hole, m.
    clamped_thickness : float
        Thickness of the clamped plate on the head side, m (sets the cone radius).
    cone_half_angle : float
        Pressure-frustum half angle, rad (30° default, Shigley).
    """

    area: float
    bolts: int
    preload: float
    head_radius: float = 5e-3
    hole_radius: float = 3.3e-3
    clamped_thickness: float = 10e-3
    cone_half_angle: float = float(np.radians(30.0))

    def __post_init__(self):
        for name in ("area", "preload", "head_radius", "hole_radius", "clamped_thickness"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0.0):
                raise InputError(name, value, "> 0")
        if self.bolts < 1:
            raise InputError("bolts", self.bolts, ">= 1")
        if self.hole_radius >= self.head_radius:
            raise InputError("hole_radius", self.hole_radius, "< head_radius")

    @property
    def cone_radius(self) -> float:
        """Outer radius of the pressure cone at the joint face, m."""
        return self.head_radius + self.clamped_thickness * np.tan(self.cone_half_angle)


def bolted_joint(face: BoltedFace, unit: UnitAreaJoint = EXAMPLE_GROUND_STEEL,
                 distribution: str = "cone-linear") -> JointDynamics:
    """Integrated normal/tangential stiffness and damping of a bolted face.

    Parameters
    ----------
    face : BoltedFace
    unit : UnitAreaJoint
        Unit-area properties vs pressure.
    distribution : {"uniform", "cone-uniform", "cone-linear"}
        ``uniform``: total preload spread over the whole face. ``cone-uniform``: each bolt's preload
        uniform over the annulus ``hole_radius < r < cone_radius``. ``cone-linear``: pressure falling
        linearly from the hole edge to zero at the cone radius (same total force). Cones are assumed
        not to overlap and to fit in the face; the contact area is capped at the face area.

    Returns
    -------
    JointDynamics
    """
    load = face.bolts * face.preload
    r0, r1 = face.hole_radius, face.cone_radius
    annulus = np.pi * (r1**2 - r0**2)
    if distribution == "uniform" or face.bolts * annulus >= face.area:
        area = face.area
        p = load / area
        values = _integrate_all(unit, lambda law: float(law(p)) * area)
    elif distribution == "cone-uniform":
        area = face.bolts * annulus
        p = face.preload / annulus
        values = _integrate_all(unit, lambda law: float(law(p)) * area)
    elif distribution == "cone-linear":
        area = face.bolts * annulus
        # p(r) = p_peak (r1 - r)/(r1 - r0); ∫ p 2πr dr = preload fixes p_peak.
        shape_integral = quad(lambda r: (r1 - r) / (r1 - r0) * 2.0 * np.pi * r, r0, r1)[0]
        p_peak = face.preload / shape_integral

        def integrate(law):
            return face.bolts * quad(lambda r: float(law(p_peak * (r1 - r) / (r1 - r0)))
                                     * 2.0 * np.pi * r, r0, r1, limit=200)[0]

        values = _integrate_all(unit, integrate)
    else:
        raise InputError("distribution", distribution, "one of uniform, cone-uniform, cone-linear")
    return JointDynamics(*values, contact_area=float(area), mean_pressure=float(load / area))


@dataclass(frozen=True)
class InterferenceFit:
    """A shaft (or ring) pressed into a hub.

    Attributes
    ----------
    diameter : float
        Nominal fit diameter, m.
    length : float
        Engagement length, m.
    interference : float
        Diametral interference, m.
    hub_outer_diameter : float
        Outer diameter of the hub (bearing seat / outer ring), m.
    shaft_inner_diameter : float
        Bore of the inner member, m (0 for a solid shaft).
    E_hub, nu_hub, E_shaft, nu_shaft : float
        Elastic constants (steel default).
    """

    diameter: float
    length: float
    interference: float
    hub_outer_diameter: float
    shaft_inner_diameter: float = 0.0
    E_hub: float = 2.06e11
    nu_hub: float = 0.3
    E_shaft: float = 2.06e11
    nu_shaft: float = 0.3

    def __post_init__(self):
        for name in ("diameter", "length", "interference", "E_hub", "E_shaft"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0.0):
                raise InputError(name, value, "> 0")
        if not self.hub_outer_diameter > self.diameter:
            raise InputError("hub_outer_diameter", self.hub_outer_diameter, "> diameter")
        if not 0.0 <= self.shaft_inner_diameter < self.diameter:
            raise InputError("shaft_inner_diameter", self.shaft_inner_diameter, "in [0, diameter)")


def lame_interference_pressure(fit: InterferenceFit) -> float:
    """Contact pressure of an interference fit by the Lamé thick-cylinder solution.

    ``p = δ / (d [ (1/E_o)((d_o² + d²)/(d_o² - d²) + ν_o) + (1/E_i)((d² + d_i²)/(d² - d_i²) - ν_i) ])``
    with ``δ`` the diametral interference (Shigley's *Mechanical Engineering Design*, press fits).

    Returns
    -------
    float
        Pa.
    """
    d, do, di = fit.diameter, fit.hub_outer_diameter, fit.shaft_inner_diameter
    hub = ((do**2 + d**2) / (do**2 - d**2) + fit.nu_hub) / fit.E_hub
    shaft = ((d**2 + di**2) / (d**2 - di**2) - fit.nu_shaft) / fit.E_shaft
    return fit.interference / (d * (hub + shaft))


def interference_fit_joint(fit: InterferenceFit, unit: UnitAreaJoint = EXAMPLE_GROUND_STEEL
                           ) -> JointDynamics:
    """Axial and radial joint properties of an interference fit (uniform Lamé pressure).

    The cylindrical face of area ``A = π d L`` carries the Lamé pressure everywhere. Axial motion
    shears the face: axial stiffness/damping are the tangential ones, ``kt A`` and ``ct A``. A radial
    translation ``u`` compresses the face by ``u cos θ`` and shears it by ``u sin θ``:
    ``K_r = (kn + kt) A / 2`` (same for damping).

    Returns
    -------
    JointDynamics
        With the convention ``kn, cn`` = **radial** and ``kt, ct`` = **axial**.
    """
    p = lame_interference_pressure(fit)
    area = np.pi * fit.diameter * fit.length
    kn, cn, kt, ct = (float(law(p)) for law in (unit.kn, unit.cn, unit.kt, unit.ct))
    return JointDynamics(kn=0.5 * (kn + kt) * area, cn=0.5 * (cn + ct) * area, kt=kt * area,
                         ct=ct * area, contact_area=float(area), mean_pressure=float(p))


def table1_ratios(rows) -> dict:
    """Column ratios of the paper's Table 1 in SI (one value per joint row).

    Parameters
    ----------
    rows : list of dict
        :func:`drakecreep.paper.tables.read_paper_table` of ``table1_bolted_fixed_joints``.

    Returns
    -------
    dict
        ``cn_over_kn_s`` (s), ``kt_over_kn`` (-), ``ct_over_kn_s`` (s), ``ct_over_kt_s`` (s),
        ``kn_N_per_m`` (for reference): arrays over the rows.
    """
    kn = np.array([r["Kn_1e10_N_per_m"] for r in rows]) * 1e10
    cn = np.array([r["Cn_1e8_Ns_per_m"] for r in rows]) * 1e8
    kt = np.array([r["Kt_1e10_N_per_m"] for r in rows]) * 1e10
    ct = np.array([r["Ct_1e8_Ns_per_m"] for r in rows]) * 1e8
    return {"cn_over_kn_s": cn / kn, "kt_over_kn": kt / kn, "ct_over_kn_s": ct / kn,
            "ct_over_kt_s": ct / kt, "kn_N_per_m": kn}


def table2_ratios(rows) -> dict:
    """Column ratios of the paper's Table 2 in SI (interference fits).

    Returns
    -------
    dict
        ``ca_over_ka_s``, ``cr_over_kr_s`` (s) and ``kr_over_ka`` (-), arrays over the rows.
    """
    ka = np.array([r["Ka_1e10_N_per_m"] for r in rows]) * 1e10
    ca = np.array([r["Ca_1e8_Ns_per_m"] for r in rows]) * 1e8
    kr = np.array([r["Kr_1e10_N_per_m"] for r in rows]) * 1e10
    cr = np.array([r["Cr_1e8_Ns_per_m"] for r in rows]) * 1e8
    return {"ca_over_ka_s": ca / ka, "cr_over_kr_s": cr / kr, "kr_over_ka": kr / ka}


#: the fixed joints the axial force passes through (Tables 1-2 row names), by element of the chain:
#: the bearing's seat (base-seat bolted face, seat-outer ring and inner ring-shaft fits, axial = normal/"a")
#: and the nut's seat (nut-seat and seat-workbench bolted faces). The guide and slider joints carry the
#: table's weight, not the axial force.
AXIAL_PATH_JOINTS = {
    "bearing_seat": (("table1_bolted_fixed_joints", "base-bearing seat"),
                     ("table2_interference_fit_joints", "bearing seat-outer ring"),
                     ("table2_interference_fit_joints", "inner ring-screw shaft")),
    "nut_seat": (("table1_bolted_fixed_joints", "workbench-nut seat"),
                 ("table1_bolted_fixed_joints", "nut-nut seat")),
}


def axial_path_joints(data_dir=None) -> dict:
    """Series stiffness and damping of the bearing-seat and nut-seat joints from the paper's Tables 1-2.

    Each group of :data:`AXIAL_PATH_JOINTS` in series (normal / axial columns ``Kn, Cn`` or ``Ka, Ca``):
    ``k = 1 / sum(1 / k_i)``, ``c = k^2 sum(c_i / k_i^2)`` (the chain's Kelvin-Voigt combination,
    :mod:`drakecreep.model.screw`). The tables' column assignment is uncertain (see the CSV notes): the
    values are what the printed columns say.

    Returns
    -------
    dict
        ``{"bearing_seat": (k N/m, c N s/m), "nut_seat": (k, c)}``; set them as
        ``screw.seat_joint_stiffness/damping`` and ``nut.seat_joint_stiffness/damping``.
    """
    from drakecreep.paper.tables import read_paper_table

    tables = {name: {r["joint"]: r for r in read_paper_table(name, data_dir)}
              for name in ("table1_bolted_fixed_joints", "table2_interference_fit_joints")}
    out = {}
    for group, members in AXIAL_PATH_JOINTS.items():
        ks, cs = [], []
        for table, joint in members:
            row = tables[table][joint]
            if table.startswith("table1"):
                ks.append(row["Kn_1e10_N_per_m"] * 1e10)
                cs.append(row["Cn_1e8_Ns_per_m"] * 1e8)
            else:
                ks.append(row["Ka_1e10_N_per_m"] * 1e10)
                cs.append(row["Ca_1e8_Ns_per_m"] * 1e8)
        k = 1.0 / sum(1.0 / x for x in ks)
        c = k**2 * sum(ci / ki**2 for ci, ki in zip(cs, ks))
        out[group] = (float(k), float(c))
    return out
