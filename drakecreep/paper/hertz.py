"""Hertz point-contact theory for the ball screw-nut pair (seed paper eqs. 12-16, Table 3).

Contact ellipse from the principal curvatures of the two bodies, following Harris & Kotzalas,
*Rolling Bearing Analysis* (5th ed., 2007, Vol. 1, ch. 6 "Contact stress and deformation"):

* curvature sum ``Σρ = ρ1x + ρ1y + ρ2x + ρ2y`` (convex positive, concave negative) and
  curvature difference ``F(ρ) = |(ρ1x - ρ1y) + (ρ2x - ρ2y)| / Σρ``;
* ellipticity ``κ = a/b`` solves ``F(ρ) = ((κ² + 1) E(e) - 2 K(e)) / ((κ² - 1) E(e))`` with
  ``e² = 1 - 1/κ²`` and ``K``, ``E`` the complete elliptic integrals (:func:`scipy.special.ellipk`,
  :func:`scipy.special.ellipe`, parameter ``m = e²``);
* dimensionless ``a* = (2κ²E/π)^(1/3)``, ``b* = (2E/(πκ))^(1/3)``, ``δ* = (2K/π)(π/(2κ²E))^(1/3)``;
* ``a = a* X^(1/3)``, ``b = b* X^(1/3)``, ``δ = δ* X^(2/3) Σρ/2`` with
  ``X = 3P/(2Σρ) · ((1-ν1²)/E1 + (1-ν2²)/E2)``.

The closed forms of Brewe & Hamrock (J. Lubr. Technol. 99(4), 1977, 485-487) are provided as a
cross-check only (:func:`brewe_hamrock_contact`).

Ball screw (paper): each ball touches the screw groove at S and the nut groove at N; both contacts
are in series along the contact normal. Axial balance (12) gives the ball load
``P = Fa / (z sin β cos λ)``; the normal approach ``δS + δN`` projects to an axial displacement
``δa = (δS + δN)/(sin β cos λ)`` (15). The paper's radial formula (16) divides by ``cos β sin λ``,
which is *not* a projection of the contact normal (whose radial component is ``cos β``); with
β = 45° it equals the circumferential component ``sin β sin λ``. Both the paper's form and a
physical radial estimate are reported by :func:`ballscrew_stiffness`.

SI units throughout (m, N, Pa, kg).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from drakecreep.errors import InputError

__all__ = [
    "Material",
    "BEARING_STEEL",
    "EllipseCoefficients",
    "PointContact",
    "ellipse_coefficients",
    "point_contact",
    "brewe_hamrock_contact",
    "BallScrewNut",
    "CONTACT_ANGLE_DEG",
    "CONTACT_ANGLE_REASON",
    "TABLE3_NUT",
    "helix_angle",
    "ball_load",
    "ballscrew_curvatures",
    "BallScrewStiffness",
    "ballscrew_stiffness",
]


@dataclass(frozen=True)
class Material:
    """Isotropic elastic material.

    Attributes
    ----------
    E : float
        Young's modulus, Pa.
    nu : float
        Poisson's ratio.
    """

    E: float
    nu: float

    @property
    def compliance(self) -> float:
        """``(1 - ν²)/E`` in 1/Pa."""
        return (1.0 - self.nu**2) / self.E


#: Through-hardened bearing steel (GCr15 / AISI 52100). The paper prints no elastic constants;
#: 206 GPa and 0.3 are the usual handbook values for this steel.
BEARING_STEEL = Material(E=2.06e11, nu=0.3)


@dataclass(frozen=True)
class EllipseCoefficients:
    """Dimensionless Hertz coefficients of one contact (Harris' notation).

    Attributes
    ----------
    curvature_sum : float
        ``Σρ``, 1/m.
    curvature_difference : float
        ``F(ρ)`` in [0, 1).
    kappa : float
        Ellipticity ``a/b`` (>= 1).
    K, E : float
        Complete elliptic integrals of the first and second kind at ``e² = 1 - 1/κ²``.
    a_star, b_star, delta_star : float
        Dimensionless semi-axes and approach.
    """

    curvature_sum: float
    curvature_difference: float
    kappa: float
    K: float
    E: float
    a_star: float
    b_star: float
    delta_star: float


def _curvature_difference_residual(kappa, target):
    m = 1.0 - 1.0 / kappa**2
    Ee = ellipe(m)
    return ((kappa**2 + 1.0) * Ee - 2.0 * ellipk(m)) / ((kappa**2 - 1.0) * Ee) - target


def ellipse_coefficients(rho_1x, rho_1y, rho_2x, rho_2y) -> EllipseCoefficients:
    """Hertz contact-ellipse coefficients from the four principal curvatures.

    Parameters
    ----------
    rho_1x, rho_1y : float
        Principal curvatures of body 1 (the ball: ``2/db`` each), 1/m.
    rho_2x, rho_2y : float
        Principal curvatures of body 2 in the same planes (concave negative), 1/m.

    Returns
    -------
    EllipseCoefficients

    Raises
    ------
    InputError
        If ``Σρ <= 0`` (no point contact, e.g. conformity ratio <= 0.5) or ``F(ρ) >= 1``.
    """
    s = float(rho_1x + rho_1y + rho_2x + rho_2y)
    if not s > 0.0:
        raise InputError("curvature_sum", s, "> 0 (convex contact; groove radius > ball radius)")
    f = abs((rho_1x - rho_1y) + (rho_2x - rho_2y)) / s
    if not f < 1.0:
        raise InputError("curvature_difference", f, "< 1 (point contact)")
    if f < 1e-12:
        kappa = 1.0
        K = E = np.pi / 2.0
    else:
        hi = 2.0
        while _curvature_difference_residual(hi, f) < 0.0:
            hi *= 2.0
        kappa = brentq(_curvature_difference_residual, 1.0 + 1e-12, hi, args=(f,),
                       xtol=1e-14, rtol=1e-13)
        m = 1.0 - 1.0 / kappa**2
        K, E = float(ellipk(m)), float(ellipe(m))
    a_star = (2.0 * kappa**2 * E / np.pi) ** (1.0 / 3.0)
    b_star = (2.0 * E / (np.pi * kappa)) ** (1.0 / 3.0)
    delta_star = (2.0 * K / np.pi) * (np.pi / (2.0 * kappa**2 * E)) ** (1.0 / 3.0)
    return EllipseCoefficients(s, f, float(kappa), float(K), float(E), a_star, b_star, delta_star)


@dataclass(frozen=True)
class PointContact:
    """Result of one Hertz point contact under normal load ``P``.

    Attributes
    ----------
    load : ndarray or float
        Normal load P, N.
    a, b : ndarray or float
        Semi-major and semi-minor axes of the contact ellipse, m.
    approach : ndarray or float
        Elastic approach of the two bodies (deformation δ), m.
    max_pressure : ndarray or float
        ``p0 = 3P/(2πab)``, Pa.
    stiffness : ndarray or float
        Tangent normal stiffness ``dP/dδ = 3P/(2δ)``, N/m.
    coefficients : EllipseCoefficients
    """

    load: np.ndarray
    a: np.ndarray
    b: np.ndarray
    approach: np.ndarray
    max_pressure: np.ndarray
    stiffness: np.ndarray
    coefficients: EllipseCoefficients


def point_contact(P, curvatures, body1: Material = BEARING_STEEL,
                  body2: Material = BEARING_STEEL) -> PointContact:
    """Hertz point contact: ellipse semi-axes, approach and pressure under normal load ``P``.

    Parameters
    ----------
    P : array_like
        Normal load(s), N (>= 0).
    curvatures : sequence of 4 floats
        ``(ρ1x, ρ1y, ρ2x, ρ2y)`` in 1/m, see :func:`ellipse_coefficients`.
    body1, body2 : Material
        Elastic constants of the two bodies.

    Returns
    -------
    PointContact
    """
    P = np.asarray(P, dtype=float)
    if np.any(P < 0.0) or not np.all(np.isfinite(P)):
        raise InputError("P", P.tolist(), "finite normal load >= 0 N")
    c = ellipse_coefficients(*curvatures)
    X = 1.5 * P / c.curvature_sum * (body1.compliance + body2.compliance)
    a = c.a_star * np.cbrt(X)
    b = c.b_star * np.cbrt(X)
    delta = c.delta_star * np.cbrt(X) ** 2 * c.curvature_sum / 2.0
    with np.errstate(invalid="ignore", divide="ignore"):
        p0 = np.where(P > 0.0, 1.5 * P / (np.pi * a * b), 0.0)
        k = np.where(P > 0.0, 1.5 * P / delta, 0.0)
    return PointContact(P[()], a[()], b[()], delta[()], p0[()], k[()], c)


def brewe_hamrock_contact(P, Rx, Ry, E_prime):
    """Brewe-Hamrock closed-form approximation of an elliptical Hertz contact (cross-check only).

    Brewe, D. E. and Hamrock, B. J., "Simplified solution for elliptical-contact deformation between
    two elastic solids", J. Lubr. Technol. 99(4):485-487, 1977:
    ``k ≈ 1.0339 (Ry/Rx)^0.6360``, ``E ≈ 1.0003 + 0.5968 Rx/Ry``, ``K ≈ 1.5277 + 0.6023 ln(Ry/Rx)``.

    Parameters
    ----------
    P : array_like
        Normal load, N.
    Rx, Ry : float
        Effective radii of curvature, ``Ry >= Rx``, m (``1/Rx = ρ1x + ρ2x`` etc.).
    E_prime : float
        ``2 / ((1-ν1²)/E1 + (1-ν2²)/E2)``, Pa.

    Returns
    -------
    dict
        ``kappa`` (a/b), ``a``, ``b`` (semi-axes, m) and ``approach`` (m).
    """
    P = np.asarray(P, dtype=float)
    alpha = Ry / Rx
    k = 1.0339 * alpha**0.6360
    Ebar = 1.0003 + 0.5968 / alpha
    Kbar = 1.5277 + 0.6023 * np.log(alpha)
    R = 1.0 / (1.0 / Rx + 1.0 / Ry)
    a = np.cbrt(6.0 * k**2 * Ebar * P * R / (np.pi * E_prime))
    b = np.cbrt(6.0 * Ebar * P * R / (np.pi * k * E_prime))
    delta = Kbar * np.cbrt(9.0 / (2.0 * Ebar * R) * (P / (np.pi * k * E_prime)) ** 2)
    return {"kappa": k, "a": a, "b": b, "approach": delta}


#: Contact angles a ball nut may have, deg: a ball screw's are 30-60 deg (45 typical); the bounds are generous. Below
#: them the ball load ``Fa/(z sin β cos λ)`` grows without bound (1e-300 deg: 7e302 N a ball, and the contact that
#: left the ball was blamed on the conformity).
CONTACT_ANGLE_DEG = (5.0, 85.0)
#: why: stated in every message that refuses a contact angle
CONTACT_ANGLE_REASON = ("a ball screw's contact angle is 30-60 deg, 45 typical, and the bounds are generous; a flatter one loads each ball with "
                        "Fa/(z sin(beta) cos(lambda)) beyond any contact")


@dataclass(frozen=True)
class BallScrewNut:
    """Geometry, material and preload of a single ball nut (defaults: paper Table 3).

    Attributes
    ----------
    balls : int
        Number of loaded balls ``z``.
    ball_diameter : float
        ``db``, m.
    nominal_diameter : float
        Screw nominal (ball-centre pitch) diameter ``d0``, m.
    contact_angle : float
        ``β``, rad.
    lead : float
        ``Ph``, m.
    conformity : float
        ``r`` = groove radius / ball radius (> 1; the paper calls it the curvature ratio).
    preload : float
        Axial force ``Fa`` carried by the balls, N.
    mass : float
        Mass used for the natural frequencies (the nut), kg.
    screw, ball, nut : Material
        Elastic constants (the paper prints none; bearing steel assumed).
    """

    balls: int = 47
    ball_diameter: float = 3.175e-3
    nominal_diameter: float = 25e-3
    contact_angle: float = float(np.radians(45.0))
    lead: float = 5e-3
    conformity: float = 1.04
    preload: float = 579.0
    mass: float = 0.335
    screw: Material = field(default=BEARING_STEEL)
    ball: Material = field(default=BEARING_STEEL)
    nut: Material = field(default=BEARING_STEEL)

    def __post_init__(self):
        checks = {
            "balls": (self.balls, self.balls >= 1, ">= 1"),
            "ball_diameter": (self.ball_diameter, 0.0 < self.ball_diameter < self.nominal_diameter,
                              "> 0 m and < nominal_diameter"),
            "nominal_diameter": (self.nominal_diameter, self.nominal_diameter > 0.0, "> 0 m"),
            "contact_angle": (self.contact_angle,
                              np.radians(CONTACT_ANGLE_DEG[0]) <= self.contact_angle <= np.radians(CONTACT_ANGLE_DEG[1]),
                              f"in [{np.radians(CONTACT_ANGLE_DEG[0]):.4g}, {np.radians(CONTACT_ANGLE_DEG[1]):.4g}] rad "
                              f"({CONTACT_ANGLE_DEG[0]:g} to {CONTACT_ANGLE_DEG[1]:g} deg: {CONTACT_ANGLE_REASON})"),
            "lead": (self.lead, self.lead > 0.0, "> 0 m"),
            "conformity": (self.conformity, self.conformity > 1.0, "> 1 (groove wider than ball)"),
            "preload": (self.preload, self.preload > 0.0, "> 0 N"),
            "mass": (self.mass, self.mass > 0.0, "> 0 kg"),
        }
        for name, (value, ok, allowed) in checks.items():
            if not (ok and np.isfinite(value)):
                raise InputError(name, value, allowed)


#: The paper's Table 3 screw-nut pair.
TABLE3_NUT = BallScrewNut()


def helix_angle(lead, nominal_diameter):
    """Helix (lead) angle ``λ = arctan(Ph / (π d0))``, rad."""
    return np.arctan(np.asarray(lead, dtype=float) / (np.pi * np.asarray(nominal_diameter, float)))


def ball_load(Fa, balls, contact_angle, helix):
    """Normal load per ball from the nut's axial balance (paper eq. 12): ``P = Fa/(z sin β cos λ)``.

    Parameters
    ----------
    Fa : array_like
        Axial force, N.
    balls : int
        Number of loaded balls ``z`` (equal sharing assumed).
    contact_angle, helix : float
        ``β`` and ``λ``, rad.

    Returns
    -------
    ndarray or float
        Ball normal load, N.
    """
    return np.asarray(Fa, dtype=float) / (balls * np.sin(contact_angle) * np.cos(helix))


def ballscrew_curvatures(nut: BallScrewNut):
    """Principal curvatures of the ball-screw (S) and ball-nut (N) contacts (paper eq. 14).

    Ball: ``2/db`` in both planes. Groove (transverse plane): ``-2/(r db)`` (concave). Along the
    helix the screw raceway is convex, ``+2 cos β cos λ/(d0 - db cos β)``, and the nut raceway
    concave, ``-2 cos β cos λ/(d0 + db cos β)``; summing gives eq. 14 with the nut sign of paper.md.

    Returns
    -------
    dict
        ``{"screw": (ρ1x, ρ1y, ρ2x, ρ2y), "nut": (...)}``, 1/m, ordered (ball along helix,
        ball transverse, raceway along helix, groove transverse).
    """
    db, d0, beta, r = nut.ball_diameter, nut.nominal_diameter, nut.contact_angle, nut.conformity
    lam = float(helix_angle(nut.lead, d0))
    c = np.cos(beta) * np.cos(lam)
    ball = 2.0 / db
    groove = -2.0 / (r * db)
    return {
        "screw": (ball, ball, 2.0 * c / (d0 - db * np.cos(beta)), groove),
        "nut": (ball, ball, -2.0 * c / (d0 + db * np.cos(beta)), groove),
    }


@dataclass(frozen=True)
class BallScrewStiffness:
    """Stiffness of the screw-nut pair from Hertz contact (see :func:`ballscrew_stiffness`).

    Attributes
    ----------
    helix : float
        ``λ``, rad.
    ball_load : float
        ``P`` per ball, N.
    screw_contact, nut_contact : PointContact
        Hertz results at S and N.
    normal_approach : float
        ``δS + δN``, m.
    axial_deflection : float
        ``δa`` (eq. 15), m.
    radial_deflection_paper : float
        ``δr`` by the paper's eq. 16, m.
    ka_tangent, ka_secant : float
        ``dFa/dδa = 3Fa/(2δa)`` and ``Fa/δa``, N/m.
    kr_paper_tangent : float
        ``3Fa/(2δr)`` with eq. 16 (the paper's definition, as far as it can be read), N/m.
    kr_physical : float
        Radial stiffness of a preloaded nut with ``z`` balls spread evenly round the screw:
        ``(z/2) k_n cos²β``, ``k_n`` the tangent normal stiffness of one ball (S and N in series), N/m.
    fa, fr_paper, fr_physical : float
        ``sqrt(K/M)/(2π)`` for the above with ``M = nut.mass``, Hz.
    """

    helix: float
    ball_load: float
    screw_contact: PointContact
    nut_contact: PointContact
    normal_approach: float
    axial_deflection: float
    radial_deflection_paper: float
    ka_tangent: float
    ka_secant: float
    kr_paper_tangent: float
    kr_physical: float
    fa: float
    fr_paper: float
    fr_physical: float


def ballscrew_stiffness(nut: BallScrewNut = TABLE3_NUT, axial_force: float | None = None
                        ) -> BallScrewStiffness:
    """Axial and radial stiffness and natural frequencies of a ball nut by Hertz theory (eqs. 12-16).

    Parameters
    ----------
    nut : BallScrewNut
        Geometry, materials, preload and mass (default: paper Table 3).
    axial_force : float, optional
        Axial force carried by the balls, N; default ``nut.preload``.

    Returns
    -------
    BallScrewStiffness

    Notes
    -----
    Because ``δ ∝ P^(2/3)``, the tangent stiffness is ``3/2`` of the secant one. All balls are
    assumed to share the load equally (no pitch errors, no nut or shaft compliance): the result is
    the contact stiffness only, an upper bound on what a hammer test on the assembled nut sees.
    """
    Fa = nut.preload if axial_force is None else float(axial_force)
    if not (np.isfinite(Fa) and Fa > 0.0):
        raise InputError("axial_force", Fa, "> 0 N")
    lam = float(helix_angle(nut.lead, nut.nominal_diameter))
    beta = nut.contact_angle
    P = float(ball_load(Fa, nut.balls, beta, lam))
    curv = ballscrew_curvatures(nut)
    s = point_contact(P, curv["screw"], nut.ball, nut.screw)
    n = point_contact(P, curv["nut"], nut.ball, nut.nut)
    radius = 0.5 * nut.ball_diameter
    # the semi-major axis grows as P^(1/3): the largest axial force whose contacts stay within the ball
    load_limit = Fa * min(radius / float(s.a), radius / float(n.a)) ** 3
    for name, c in (("screw", s), ("nut", n)):
        # Hertz theory takes the contact as small against the bodies; an ellipse longer than the ball is none
        # (conformity 1.0000000001 gave a = 314 mm on a 3.175 mm ball, and an axial stiffness 1900 x the paper's)
        if not float(c.a) < radius:
            err = InputError("conformity", nut.conformity,
                             f"a groove that keeps the contact within the ball: the {name} contact's semi-major axis "
                             f"is {float(c.a) * 1e3:.4g} mm at a ball load of {P:.4g} N, beyond the ball's radius "
                             f"{radius * 1e3:.4g} mm, where Hertz theory does not apply (a larger conformity, a larger "
                             f"ball or an axial force below {load_limit:.4g} N)")
            err.load_limit = load_limit  # N: the axial force this groove and ball carry within Hertz theory
            raise err
    delta = float(s.approach + n.approach)
    da = delta / (np.sin(beta) * np.cos(lam))
    dr = delta / (np.cos(beta) * np.sin(lam))
    ka_t = 1.5 * Fa / da
    kr_p = 1.5 * Fa / dr
    k_ball = 1.0 / (1.0 / float(s.stiffness) + 1.0 / float(n.stiffness))
    kr_phys = 0.5 * nut.balls * k_ball * np.cos(beta) ** 2

    def freq(k):
        return float(np.sqrt(k / nut.mass) / (2.0 * np.pi))

    return BallScrewStiffness(
        helix=lam, ball_load=P, screw_contact=s, nut_contact=n, normal_approach=delta,
        axial_deflection=da, radial_deflection_paper=dr, ka_tangent=ka_t, ka_secant=Fa / da,
        kr_paper_tangent=kr_p, kr_physical=float(kr_phys), fa=freq(ka_t), fr_paper=freq(kr_p),
        fr_physical=freq(kr_phys),
    )
