"""Cam motion laws and cam programmes (rise, dwell, return) over one revolution.

A *motion law* is a normalised displacement s(z) on the normalised segment angle
z ∈ [0, 1] with s(0) = 0 and s(1) = 1; its derivatives s', s'', s''' are taken with
respect to z. A *cam programme* (:class:`CamProfile`) strings segments of angular length
β and lift h together; on a segment starting at φ_s,

    U(φ) = U_s + h s(z),  z = (φ − φ_s)/β,  U^(k)(φ) = h s^(k)(z)/β^k,

which gives a position function U(φ) with exact derivatives U', U'', U''' (see
:mod:`femmech.mechanisms.position`).

All laws except the polynomials (3-4-5, 4-5-6-7) have a piecewise sinusoidal
acceleration a(z) = c + A sin(ω(z − z_k) + θ) on pieces [z_k, z_k+1]; they are
integrated in closed form, so every derivative is exact to round-off.

Laws by name: :data:`LAWS` and :func:`motion_law`. A rise–dwell–return–dwell programme
from its angles in degrees and its stroke: :func:`cam_program` (also
:meth:`CamProfile.from_program`). Every profile lists the angles where a derivative of
U may jump (:meth:`CamProfile.breakpoints`: the segment joints and the piece joints
inside the piecewise laws); the cycle integrators (:mod:`femmech.analysis.magnus`)
start a step at each of them, because a step across a jump loses the order of the
scheme.

References
----------
.. [1] R. L. Norton, *Cam Design and Manufacturing Handbook*, 2nd ed., Industrial Press,
   2009, ch. 3 (double-dwell functions) and Table 3-3 (peak values of s', s'', s''').
.. [2] H. A. Rothbart, *Cam Design Handbook*, McGraw-Hill, 2004, ch. 2.

Uses only mechanisms.position.
"""

from dataclasses import dataclass, field

import numpy as np

from femmech.mechanisms.position import as_angles, check_order

__all__ = [
    "CamProfile",
    "CamSegment",
    "MotionLaw",
    "PolynomialLaw",
    "SinusoidalLaw",
    "LAWS",
    "cam_program",
    "cycloidal",
    "harmonic",
    "modified_sine",
    "modified_trapezoid",
    "motion_law",
    "polynomial_345",
    "polynomial_4567",
]

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class PolynomialLaw:
    """Polynomial motion law s(z) = Σ_k a_k z^k on z ∈ [0, 1].

    Parameters
    ----------
    name : str
        Name used in messages and plots.
    coefficients : tuple of float
        a_0, a_1, ... (dimensionless); s(0) = 0 and s(1) = 1 are checked.
    continuity : int
        Highest derivative order that is continuous at a joint with a dwell
        (1: velocity, 2: acceleration).
    """

    name: str
    coefficients: tuple[float, ...]
    continuity: int

    def __post_init__(self):
        poly = np.polynomial.Polynomial(self.coefficients)
        if abs(poly(0.0)) > 1e-12 or abs(poly(1.0) - 1.0) > 1e-12:
            raise ValueError(f"motion law {self.name!r}: need s(0) = 0 and s(1) = 1")

    def evaluate(self, z) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(s, s', s'', s''')`` at normalised angles ``z`` (any shape, in [0, 1])."""
        z = np.asarray(z, dtype=float)
        poly = np.polynomial.Polynomial(self.coefficients)
        return tuple(poly.deriv(k)(z) if k else poly(z) for k in range(4))

    def integral(self, z) -> np.ndarray:
        """Return ``∫₀^z s(u) du`` at normalised angles ``z`` (any shape, in [0, 1])."""
        return np.polynomial.Polynomial(self.coefficients).integ()(np.asarray(z, dtype=float))

    def joints(self) -> np.ndarray:
        """Normalised angles in (0, 1) where s, ..., s''' jump: none (a polynomial)."""
        return np.zeros(0)


@dataclass(frozen=True)
class SinusoidalLaw:
    """Motion law with piecewise sinusoidal acceleration, integrated in closed form.

    On piece k, with Δ = z − z_k and x = ω_k Δ + θ_k (Norton [1]_, ch. 3):

        s''' = A ω cos x,   s'' = c + A sin x,
        s'   = v_k + c Δ − (A/ω)(cos x − cos θ),
        s    = s_k + v_k Δ + c Δ²/2 − (A/ω)[(sin x − sin θ)/ω − Δ cos θ].

    Build instances with :func:`harmonic`, :func:`cycloidal`, :func:`modified_sine` or
    :func:`modified_trapezoid`; the constructor takes the already normalised pieces.

    Parameters
    ----------
    name : str
        Name used in messages and plots.
    starts, const, amp, omega, phase, s_start, v_start : tuple of float
        Per piece: start z_k, constant c, amplitude A, circular frequency ω (per unit z),
        phase θ, and s, s' at the piece start.
    continuity : int
        Highest derivative order continuous at a joint with a dwell.
    """

    name: str
    starts: tuple[float, ...]
    const: tuple[float, ...]
    amp: tuple[float, ...]
    omega: tuple[float, ...]
    phase: tuple[float, ...]
    s_start: tuple[float, ...]
    v_start: tuple[float, ...]
    continuity: int

    def evaluate(self, z) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(s, s', s'', s''')`` at normalised angles ``z`` (any shape, in [0, 1]).

        At an interior piece boundary the right-hand piece is used.
        """
        z = np.asarray(z, dtype=float)
        k = np.clip(np.searchsorted(self.starts, z, side="right") - 1, 0, len(self.starts) - 1)
        c, a, w, th = (np.asarray(p)[k] for p in (self.const, self.amp, self.omega, self.phase))
        s0, v0 = np.asarray(self.s_start)[k], np.asarray(self.v_start)[k]
        d = z - np.asarray(self.starts)[k]
        x = w * d + th
        s3 = a * w * np.cos(x)
        s2 = c + a * np.sin(x)
        s1 = v0 + c * d - a / w * (np.cos(x) - np.cos(th))
        s = s0 + v0 * d + 0.5 * c * d**2 - a / w * ((np.sin(x) - np.sin(th)) / w - d * np.cos(th))
        return s, s1, s2, s3

    def _piece_integral(self, k, d) -> np.ndarray:
        """``∫₀^d s(z_k + u) du`` on piece(s) k (int array) for lengths d (same shape).

        With x = ω d + θ, the integral of :meth:`evaluate`'s s:
        s_k d + v_k d²/2 + c d³/6 − (A/ω)[(cos θ − cos x)/ω² − d sin θ/ω − d² cos θ/2].
        """
        c, a, w, th = (np.asarray(p)[k] for p in (self.const, self.amp, self.omega, self.phase))
        s0, v0 = np.asarray(self.s_start)[k], np.asarray(self.v_start)[k]
        x = w * d + th
        return (s0 * d + 0.5 * v0 * d**2 + c * d**3 / 6
                - a / w * ((np.cos(th) - np.cos(x)) / w**2 - d * np.sin(th) / w
                           - 0.5 * d**2 * np.cos(th)))

    def integral(self, z) -> np.ndarray:
        """Return ``∫₀^z s(u) du`` at normalised angles ``z`` (any shape, in [0, 1])."""
        z = np.asarray(z, dtype=float)
        starts = np.asarray(self.starts)
        pieces = np.arange(starts.size)
        lengths = np.diff(np.append(starts, 1.0))
        before = np.concatenate([[0.0], np.cumsum(self._piece_integral(pieces, lengths))])
        k = np.clip(np.searchsorted(starts, z, side="right") - 1, 0, starts.size - 1)
        return before[k] + self._piece_integral(k, z - starts[k])

    def joints(self) -> np.ndarray:
        """Normalised angles in (0, 1) of the interior piece boundaries (s''' may jump)."""
        return np.asarray(self.starts[1:], dtype=float)


def _sinusoidal_law(name: str, pieces, continuity: int) -> SinusoidalLaw:
    """Integrate unscaled pieces ``(z_k, c, A, ω, θ)`` from rest and normalise s(1) = 1."""
    starts, const, amp, omega, phase = (tuple(float(p[i]) for p in pieces) for i in range(5))
    raw = SinusoidalLaw(name, starts, const, amp, omega, phase, (0.0,) * len(starts),
                        (0.0,) * len(starts), continuity)
    s_start, v_start = [0.0], [0.0]
    for k in range(1, len(starts)):
        # value at the end of piece k-1, evaluated with piece k-1's own constants
        piece = SinusoidalLaw(name, starts[k - 1:k], const[k - 1:k], amp[k - 1:k],
                              omega[k - 1:k], phase[k - 1:k], (s_start[-1],), (v_start[-1],),
                              continuity)
        s, v, _, _ = piece.evaluate(np.array([starts[k]]))
        s_start.append(float(s[0]))
        v_start.append(float(v[0]))
    raw = SinusoidalLaw(name, starts, const, amp, omega, phase, tuple(s_start), tuple(v_start),
                        continuity)
    s_end, v_end, _, _ = raw.evaluate(np.array([1.0]))
    if abs(v_end[0]) > 1e-12 * abs(s_end[0]):
        raise ValueError(f"motion law {name!r} does not end at rest: s'(1) = {v_end[0]:.3g}")
    scale = 1.0 / float(s_end[0])
    return SinusoidalLaw(name, starts, tuple(scale * c for c in const),
                         tuple(scale * a for a in amp), omega, phase,
                         tuple(scale * s for s in s_start), tuple(scale * v for v in v_start),
                         continuity)


def harmonic() -> SinusoidalLaw:
    """Return the harmonic rise s = (1 − cos πz)/2; acceleration jumps at a dwell (C¹)."""
    return _sinusoidal_law("harmonic", [(0.0, 0.0, 1.0, np.pi, np.pi / 2)], continuity=1)


def cycloidal() -> SinusoidalLaw:
    """Return the cycloidal rise s = z − sin(2πz)/(2π); continuous acceleration, jerk jumps (C²)."""
    return _sinusoidal_law("cycloidal", [(0.0, 0.0, 1.0, TWO_PI, 0.0)], continuity=2)


def modified_sine() -> SinusoidalLaw:
    """Return the modified sine law: quarter sine waves on z ∈ [0, 1/8] ∪ [7/8, 1].

    The middle piece is a sine of period 3/2 (Norton [1]_, sec. 3.8); class C².
    """
    pieces = [(0.0, 0.0, 1.0, 4 * np.pi, 0.0),
              (1 / 8, 0.0, 1.0, 4 * np.pi / 3, np.pi / 2),
              (7 / 8, 0.0, -1.0, 4 * np.pi, np.pi / 2)]
    return _sinusoidal_law("modified sine", pieces, continuity=2)


def modified_trapezoid() -> SinusoidalLaw:
    """Return the modified trapezoid law: constant acceleration blended by sine quarter waves (C²).

    Pieces at z = 0, 1/8, 3/8, 5/8, 7/8 (Norton [1]_, sec. 3.7).
    """
    pieces = [(0.0, 0.0, 1.0, 4 * np.pi, 0.0),
              (1 / 8, 1.0, 0.0, 1.0, 0.0),
              (3 / 8, 0.0, 1.0, 4 * np.pi, np.pi / 2),
              (5 / 8, -1.0, 0.0, 1.0, 0.0),
              (7 / 8, 0.0, -1.0, 4 * np.pi, np.pi / 2)]
    return _sinusoidal_law("modified trapezoid", pieces, continuity=2)


def polynomial_345() -> PolynomialLaw:
    """Return the 3-4-5 law s = 10z³ − 15z⁴ + 6z⁵; acceleration continuous, jerk jumps (C²)."""
    return PolynomialLaw("3-4-5 polynomial", (0.0, 0.0, 0.0, 10.0, -15.0, 6.0), continuity=2)


def polynomial_4567() -> PolynomialLaw:
    """Return the 4-5-6-7 law s = 35z⁴ − 84z⁵ + 70z⁶ − 20z⁷; jerk continuous (C³).

    The polynomial of degree 7 with s(0) = 0, s(1) = 1 and s', s'', s''' zero at both
    ends (Norton [1]_, sec. 3.10; Rothbart [2]_, ch. 2).
    """
    return PolynomialLaw("4-5-6-7 polynomial", (0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0),
                         continuity=3)


MotionLaw = PolynomialLaw | SinusoidalLaw

LAWS = {"cycloidal": cycloidal, "harmonic": harmonic, "modified_sine": modified_sine,
        "modified_trapezoid": modified_trapezoid, "polynomial_345": polynomial_345,
        "polynomial_4567": polynomial_4567}
"""The motion laws by name (their constructors); :func:`motion_law` also accepts
"3-4-5", "4-5-6-7", and spaces or hyphens for underscores ("modified sine")."""

_ALIASES = {"3_4_5": "polynomial_345", "345": "polynomial_345", "4_5_6_7": "polynomial_4567",
            "4567": "polynomial_4567", "simple_harmonic": "harmonic"}


def motion_law(law) -> MotionLaw:
    """Return a motion law given by name (a key of :data:`LAWS`) or as a law object.

    Raises ``ValueError`` for an unknown name, listing the known ones.
    """
    if isinstance(law, PolynomialLaw | SinusoidalLaw):
        return law
    if not isinstance(law, str):
        raise TypeError(f"a motion law is a name or a law object, got {type(law).__name__}")
    key = law.strip().lower().replace("-", "_").replace(" ", "_")
    key = _ALIASES.get(key, key)
    if key not in LAWS:
        raise ValueError(f"unknown motion law {law!r}; known laws: {', '.join(LAWS)}"
                         " (also '3-4-5', '4-5-6-7')")
    return LAWS[key]()


@dataclass(frozen=True)
class CamSegment:
    """One segment of a cam programme.

    Parameters
    ----------
    beta : float
        Angular extent of the segment, rad, > 0.
    lift : float
        Change of the output over the segment (m for a translating follower, rad for a
        rocker): > 0 rise, < 0 return, 0 dwell.
    law : MotionLaw or None
        Normalised motion law; required unless ``lift == 0``.
    """

    beta: float
    lift: float = 0.0
    law: MotionLaw | None = None


def _check_segments(segments: tuple[CamSegment, ...]) -> None:
    """Raise ValueError for segments that do not form a periodic programme over 2π."""
    if not segments:
        raise ValueError("a cam profile needs at least one segment")
    for i, seg in enumerate(segments):
        if not (np.isfinite(seg.beta) and seg.beta > 0):
            raise ValueError(f"segment {i}: beta must be a positive angle in rad, got {seg.beta}")
        if seg.lift != 0 and seg.law is None:
            raise ValueError(f"segment {i}: lift {seg.lift} needs a motion law")
    total = sum(seg.beta for seg in segments)
    if abs(total - TWO_PI) > 1e-9:
        raise ValueError(f"segment angles beta sum to {total!r} rad, not 2*pi "
                         f"(difference {total - TWO_PI:.3g} rad)")
    lifts = [seg.lift for seg in segments]
    if abs(sum(lifts)) > 1e-12 * max(1.0, max(abs(h) for h in lifts)):
        raise ValueError(f"segment lifts sum to {sum(lifts):.6g}, not 0: the profile "
                         "U(phi) would not be periodic")


@dataclass(frozen=True)
class CamProfile:
    """Cam programme over one revolution, a periodic position function U(φ).

    Parameters
    ----------
    segments : tuple of CamSegment
        Consecutive segments; their ``beta`` sum to 2π and their ``lift`` sum to 0.
    phi_start : float
        Drive angle (rad) at which the first segment starts.
    base : float
        Output value U at ``phi_start`` (m or rad).

    Notes
    -----
    At a joint between segments, the segment that starts there is evaluated, so
    derivatives that jump (e.g. U''' of the 3-4-5 law) take their right-hand limit.

    Examples
    --------
    >>> import numpy as np
    >>> cam = CamProfile((CamSegment(np.pi / 2, 0.01, cycloidal()), CamSegment(np.pi / 2),
    ...                   CamSegment(np.pi / 2, -0.01, cycloidal()), CamSegment(np.pi / 2)))
    >>> float(cam(np.pi / 4)), float(cam(3 * np.pi / 4))
    (0.005, 0.01)
    """

    segments: tuple[CamSegment, ...]
    phi_start: float = 0.0
    base: float = 0.0
    _starts: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "segments", tuple(self.segments))
        _check_segments(self.segments)
        starts = np.concatenate([[0.0], np.cumsum([s.beta for s in self.segments])[:-1]])
        object.__setattr__(self, "_starts", tuple(starts))

    @classmethod
    def from_program(cls, stroke: float, rise: float, dwell_top: float, return_: float,
                     dwell_bottom: float = 0.0, law="cycloidal", return_law=None,
                     start: float = 0.0, base: float = 0.0) -> "CamProfile":
        """Rise–dwell–return–dwell programme, angles in degrees: :func:`cam_program`."""
        return cam_program(stroke, rise, dwell_top, return_, dwell_bottom, law, return_law,
                           start, base)

    def derivatives(self, phi) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(U, U', U'', U''')`` at drive angles ``phi`` (rad, any shape).

        Units: output unit (m or rad) per rad^k for U^(k).
        """
        phi = as_angles(phi)
        psi = np.mod(phi - self.phi_start, TWO_PI)
        index = np.clip(np.searchsorted(self._starts, psi, side="right") - 1, 0,
                        len(self.segments) - 1)
        out = [np.zeros_like(psi) for _ in range(4)]
        level = self.base
        for i, seg in enumerate(self.segments):
            mask = index == i
            out[0][mask] = level
            if seg.lift != 0 and np.any(mask):
                z = np.clip((psi[mask] - self._starts[i]) / seg.beta, 0.0, 1.0)
                for k, s_k in enumerate(seg.law.evaluate(z)):
                    out[k][mask] += seg.lift * s_k / seg.beta**k
            level += seg.lift
        return tuple(out)

    def __call__(self, phi, order: int = 0) -> np.ndarray:
        """Return U^(order)(φ) at ``phi`` (rad); ``order`` is 0, 1, 2 or 3."""
        return self.derivatives(phi)[check_order(order)]

    def breakpoints(self) -> np.ndarray:
        """Drive angles in [0, 2π), rad, where U, U', U'' or U''' may jump, sorted.

        The segment joints (where a law meets a dwell the jerk jumps, with the harmonic law
        the acceleration too) and the piece boundaries inside piecewise laws. Time
        integrators over the cycle put step boundaries there: a step across a jump loses
        the order of the scheme (:mod:`femmech.analysis.magnus`).
        """
        angles = [np.asarray(self._starts)]
        for start, seg in zip(self._starts, self.segments, strict=True):
            if seg.law is not None and seg.lift != 0:
                angles.append(start + seg.beta * seg.law.joints())
        return np.unique(np.mod(self.phi_start + np.concatenate(angles), TWO_PI))


def cam_program(stroke: float, rise: float, dwell_top: float, return_: float,
                dwell_bottom: float = 0.0, law="cycloidal", return_law=None,
                start: float = 0.0, base: float = 0.0) -> CamProfile:
    """Rise–dwell–return–dwell cam programme from its angles in degrees.

    The follower rises by ``stroke`` over ``rise`` degrees with ``law``, dwells at the
    top for ``dwell_top``, returns over ``return_`` with ``return_law`` (default: the
    rise law) and dwells at the bottom for ``dwell_bottom``. Zero dwells are left out
    (rise and return then meet; :meth:`CamProfile.breakpoints` lists every joint).

    Parameters
    ----------
    stroke : float
        Lift of the follower, m (translating) or rad (rocker), non-zero; negative for a
        programme that falls first.
    rise, dwell_top, return_, dwell_bottom : float
        Segment angles, degrees (deg): rise and return > 0, dwells >= 0, sum 360.
    law, return_law : str or MotionLaw
        A name of :data:`LAWS` (``"cycloidal"``, ``"harmonic"``, ``"modified_sine"``,
        ``"modified_trapezoid"``, ``"polynomial_345"``, ``"polynomial_4567"``) or a law.
    start : float
        Drive angle where the rise starts, degrees.
    base : float
        Follower position in the bottom dwell (m or rad).

    Returns
    -------
    CamProfile

    Examples
    --------
    >>> cam = cam_program(0.02, rise=90, dwell_top=90, return_=90, dwell_bottom=90)
    >>> [round(float(x), 6) for x in np.rad2deg(cam.breakpoints())]
    [0.0, 90.0, 180.0, 270.0]
    """
    angles = {"rise": rise, "dwell_top": dwell_top, "return_": return_,
              "dwell_bottom": dwell_bottom}
    for name, value in angles.items():
        if not np.isfinite(value) or value < 0:
            raise ValueError(f"cam programme: {name} must be a finite angle >= 0 deg,"
                             f" got {value}")
    for name in ("rise", "return_"):
        if angles[name] == 0:
            raise ValueError(f"cam programme: {name} must be > 0 deg")
    total = sum(angles.values())
    if abs(total - 360.0) > 1e-9:
        raise ValueError(f"cam programme: the angles rise + dwell_top + return_ +"
                         f" dwell_bottom sum to {total!r} deg, not 360 (difference"
                         f" {total - 360.0:.3g} deg)")
    if not (np.isfinite(stroke) and stroke != 0):
        raise ValueError(f"cam programme: stroke must be finite and non-zero, got {stroke}")
    up, down = motion_law(law), motion_law(law if return_law is None else return_law)
    pieces = ((rise, stroke, up), (dwell_top, 0.0, None), (return_, -stroke, down),
              (dwell_bottom, 0.0, None))
    segments = tuple(CamSegment(np.deg2rad(beta), lift, f) for beta, lift, f in pieces
                     if beta > 0)
    return CamProfile(segments, phi_start=np.deg2rad(start), base=base)
