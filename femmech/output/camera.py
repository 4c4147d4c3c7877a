"""Cameras for mode images: named views, a fit that shows given points whole, screen axes.

Pure numpy (no pyvista). A camera is fitted once per model to the points of every mode
it will draw (undeformed model and the deformed shapes at their scales), so that all
images of one model share one camera and nothing leaves the frame.

The fit is exact for a perspective camera of fixed direction: with the points in camera
axes (right ``x``, up ``y``, depth ``z``), a point is inside the image when
``|x - c_x| <= k_x (z + D)`` and ``|y - c_y| <= k_y (z + D)`` with
``k = (1 - margin) tan(view angle / 2)`` (times the aspect ratio for ``x``); these are
linear in the camera's lateral offset ``c`` and distance ``D``, and the smallest ``D``
and its centred ``c`` follow in closed form (:func:`fit_camera`).

Uses nothing of femmech.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

VIEWS = {
    "iso": ((1.0, 1.0, 1.0), (0.0, 0.0, 1.0)),
    "xy": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "xz": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "yz": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
}
"""Named views: (direction from the model to the camera, view-up), as pyvista's
``view_isometric``, ``view_xy``, ``view_xz`` and ``view_yz``."""
VIEW_ANGLE = 30.0
"""Vertical view angle of the perspective camera, degrees (VTK's default)."""
MARGIN = 0.06
"""Free border of the image around the fitted points, as a fraction of its half-size."""


@dataclass(frozen=True)
class Camera:
    """A perspective camera.

    Attributes
    ----------
    position, focal_point, view_up : ndarray (3,)
        Camera position and focal point (m) and the view-up unit vector.
    view_angle : float
        Vertical view angle, degrees.
    """

    position: np.ndarray
    focal_point: np.ndarray
    view_up: np.ndarray
    view_angle: float = VIEW_ANGLE

    def as_pyvista(self) -> list[tuple[float, float, float]]:
        """``[position, focal point, view up]`` for ``pyvista.Plotter.camera_position``."""
        return [tuple(map(float, v)) for v in (self.position, self.focal_point, self.view_up)]

    def axes(self) -> np.ndarray:
        """Rows: screen right, screen up and viewing direction (unit vectors), (3, 3)."""
        return _frame(np.asarray(self.position) - self.focal_point, self.view_up)


def check_view(camera) -> None:
    """ValueError for a view name that :data:`VIEWS` does not know."""
    if isinstance(camera, str) and camera not in VIEWS:
        raise ValueError(f"unknown camera {camera!r}; use one of {sorted(VIEWS)} or a"
                         " pyvista camera position")


def _frame(to_camera, up) -> np.ndarray:
    """Right, up and viewing direction (rows) for a camera looking against ``to_camera``."""
    d = -np.asarray(to_camera, dtype=float)
    d /= np.linalg.norm(d)
    u = np.asarray(up, dtype=float) - (np.dot(up, d)) * d
    if np.linalg.norm(u) < 1e-9:  # view-up along the view: take any normal
        u = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    return np.array([np.cross(d, u), u, d])


def fit_camera(points: np.ndarray, view="iso", aspect: float = 4 / 3,
               margin: float = MARGIN, view_angle: float = VIEW_ANGLE) -> Camera:
    """The nearest camera looking along ``view`` that shows all ``points``, centred.

    Parameters
    ----------
    points : ndarray (n, 3)
        Points that must be inside the image, m.
    view : str or (to-camera vector, view-up)
        A name of :data:`VIEWS` or two 3-vectors.
    aspect : float
        Image width / height.
    margin : float
        Free border, fraction of the image's half-width and half-height (0..1).
    view_angle : float
        Vertical view angle, degrees.

    Returns
    -------
    Camera
        Every point projects inside ``[-(1 - margin), 1 - margin]`` in both normalised
        image coordinates (see the module notes), and the extreme points touch that
        box on two opposite sides of the tighter direction.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    check_view(view)
    to_camera, up = VIEWS[view] if isinstance(view, str) else view
    axes = _frame(to_camera, up)
    origin = points.mean(axis=0)
    x, y, z = ((points - origin) @ axes.T).T
    t = (1.0 - margin) * np.tan(np.radians(view_angle) / 2.0)
    distance, centre = [], []
    for lateral, k in ((x, t * aspect), (y, t)):
        low, high = np.max(lateral - k * z), np.min(lateral + k * z)
        distance.append((low - high) / (2.0 * k))
        centre.append(0.5 * (low + high))
    extent = float(np.ptp(points, axis=0).max()) or 1.0
    D = max(max(distance), 0.1 * extent - float(z.min()))
    focal = origin + centre[0] * axes[0] + centre[1] * axes[1]
    return Camera(focal - D * axes[2], focal, axes[1], float(view_angle))


def camera_from_position(position, view_angle: float = VIEW_ANGLE) -> Camera:
    """A :class:`Camera` from a pyvista camera position ``[position, focal point, up]``."""
    try:
        pos, focal, up = (np.asarray(v, dtype=float).reshape(3) for v in position)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"camera must be a view name or [position, focal point, view up]"
                         f" (three 3-vectors), got {position!r}") from exc
    return Camera(pos, focal, up, float(view_angle))


def project(camera: Camera, points: np.ndarray, aspect: float) -> np.ndarray:
    """Normalised image coordinates (n, 2) of points, (-1, -1) bottom left to (1, 1)."""
    axes = camera.axes()
    rel = (np.asarray(points, dtype=float).reshape(-1, 3) - camera.position) @ axes.T
    t = np.tan(np.radians(camera.view_angle) / 2.0)
    return np.column_stack([rel[:, 0] / (rel[:, 2] * t * aspect), rel[:, 1] / (rel[:, 2] * t)])


def screen_axes(camera: Camera) -> np.ndarray:
    """Components of the global x, y, z axes (rows) along screen right, screen up and
    into the screen, (3, 3): a parallel projection of the unit axes for the orientation
    triad of an image (an axis along the viewing direction has no screen length)."""
    return camera.axes().T
