"""An orbit camera (orbit, pan, zoom, frame all, follow) and mouse picking, and the
camera a command line chooses (`CameraChoice`: `play --camera`).

Pure numpy: matrices are column-vector convention (p_clip = P @ V @ p_world) and are
sent to OpenGL transposed (column-major).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ecs_tentacles.numeric.quaternions import cross

CAMERA_RULE = "frame-all, follow NAME or X,Y,Z,TX,TY,TZ (eye, then the point looked at)"
FIT_BORDER = 0.06  # share of the picture left free round what `fit` frames
_DIRECTIONS = 96  # directions whose extreme points stand for a large point set in `fit`


@dataclass(frozen=True)
class CameraChoice:
    """Where a command line puts the camera: `kind` "frame-all" (every creature and goal
    in view, kept so in a headless run), "follow" (`name`'s creature at the centre) or
    "fixed" (from `eye` looking at `target`)."""

    kind: str
    name: str | None = None
    eye: tuple[float, float, float] | None = None
    target: tuple[float, float, float] | None = None


def parse_camera(text: str) -> CameraChoice:
    """`frame-all`, `follow NAME` (or `follow=NAME`) or `X,Y,Z,TX,TY,TZ`; ValueError (one
    line, what was wrong) otherwise."""
    words = text.strip()
    if words == "frame-all":
        return CameraChoice("frame-all")
    for joint in (" ", "=", ":"):
        if words.startswith(f"follow{joint}"):
            name = words[len("follow") + 1 :].strip()
            if name:
                return CameraChoice("follow", name=name)
    if words == "follow":
        raise ValueError("follow needs a creature's name: follow NAME")
    parts = words.split(",")
    if len(parts) != 6:
        raise ValueError(f"must be {CAMERA_RULE}, got {text!r}")
    try:
        numbers = [float(part) for part in parts]
    except ValueError:
        raise ValueError(f"must be {CAMERA_RULE}, got {text!r}") from None
    if not np.isfinite(numbers).all():
        raise ValueError(f"the six numbers must be finite, got {text!r}")
    eye, target = np.array(numbers[:3]), np.array(numbers[3:])
    offset = eye - target
    length = float(np.linalg.norm(offset))
    if length < 1e-6:
        raise ValueError(f"the eye and the point looked at are the same point, got {text!r}")
    if abs(offset[2]) / length > np.sin(OrbitCamera.MAX_PITCH):
        raise ValueError(f"looks straight up or down (tilt it a little), got {text!r}")
    return CameraChoice("fixed", eye=tuple(numbers[:3]), target=tuple(numbers[3:]))  # type: ignore[arg-type]


FIT_TOLERANCE = 1e-4  # relative: the bisection of a fitting distance stops this close


def perspective(fov_y: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / np.tan(fov_y / 2)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = f
    m[2, 2] = (far + near) / (near - far)
    m[2, 3] = 2 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray) -> np.ndarray:
    forward = target - eye
    forward = forward / np.linalg.norm(forward)
    right = cross(forward, up)
    right = right / np.linalg.norm(right)
    true_up = cross(right, forward)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = right, true_up, -forward
    m[:3, 3] = -m[:3, :3] @ eye
    return m


@dataclass
class OrbitCamera:
    """Looks at `target` from `distance`, turned by `yaw` about +z and tilted by `pitch`."""

    width: int = 1280
    height: int = 720
    target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    distance: float = 3.0
    yaw: float = np.radians(-60.0)
    pitch: float = np.radians(35.0)
    fov_y: float = np.radians(45.0)
    follow: int | None = None  # transform row to keep centred
    shift_x: float = 0.0  # pixels to move the picture's centre right (to clear a side panel)

    MIN_PITCH = np.radians(3.0)
    MAX_PITCH = np.radians(89.0)

    @property
    def eye(self) -> np.ndarray:
        cp = np.cos(self.pitch)
        offset = np.array([cp * np.cos(self.yaw), cp * np.sin(self.yaw), np.sin(self.pitch)])
        return self.target + self.distance * offset

    @property
    def per_metre(self) -> float:
        """Metres one pixel spans 1 m from the eye (times a distance: a pixel's size there)."""
        return float(2.0 * np.tan(self.fov_y / 2) / self.height)

    def view(self) -> np.ndarray:
        return look_at(self.eye, self.target, np.array([0.0, 0.0, 1.0]))

    def projection(self) -> np.ndarray:
        near = max(0.01, self.distance * 0.01)
        matrix = perspective(self.fov_y, self.width / self.height, near, self.distance * 50 + 50)
        matrix[0, 2] = -2.0 * self.shift_x / self.width  # lens shift: x_ndc += 2 shift / width
        return matrix

    def view_projection(self) -> np.ndarray:
        matrix: np.ndarray = self.projection() @ self.view()
        return matrix

    def orbit(self, dx: float, dy: float) -> None:
        """Turn by mouse motion in pixels."""
        self.yaw -= dx * 0.008
        self.pitch = float(np.clip(self.pitch - dy * 0.008, self.MIN_PITCH, self.MAX_PITCH))

    def pan(self, dx: float, dy: float) -> None:
        """Slide the target in the view plane by mouse motion in pixels."""
        view = self.view()
        right, up = view[0, :3], view[1, :3]
        scale = self.distance * np.tan(self.fov_y / 2) * 2 / self.height
        self.target = self.target - (right * dx + up * dy) * scale
        self.follow = None

    def zoom(self, steps: float) -> None:
        """Move closer (positive steps) or farther."""
        self.distance = float(np.clip(self.distance * 0.9**steps, 0.2, 500.0))

    def frame(self, points: np.ndarray, margin: float = 1.3) -> None:
        """Centre on `points` (n, 3) and back off until they all fit."""
        if not len(points):
            return
        low, high = points.min(axis=0), points.max(axis=0)
        self.target = (low + high) / 2
        self.target[2] = 0.0
        radius = max(float(np.linalg.norm(high - low)) / 2, 0.3)
        self.distance = margin * radius / np.sin(self.fov_y / 2)

    def look_from(self, eye: np.ndarray, target: np.ndarray) -> None:
        """Stand at `eye` and look at `target` (both world points; no follow)."""
        eye, target = np.asarray(eye, dtype=np.float64), np.asarray(target, dtype=np.float64)
        offset = eye - target
        self.target = target.copy()
        self.distance = float(np.linalg.norm(offset))
        self.yaw = float(np.arctan2(offset[1], offset[0]))
        self.pitch = float(np.arcsin(np.clip(offset[2] / self.distance, -1.0, 1.0)))
        self.follow = None

    def fit(self, points: np.ndarray, border: float = FIT_BORDER) -> None:
        """Centre on `points` (n, 3) and come as close as keeps every one of them inside
        the picture's free part (right of the side panel, `shift_x`), `border` of it
        left round them; the view's direction stays."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if not len(points):
            return
        if len(points) > 4 * _DIRECTIONS:  # the hull's extreme points decide the framing
            # direction by direction along contiguous rows: 10x faster than along columns
            points = points[np.unique(np.argmax(_sphere_directions() @ points.T, axis=1))]
        self.frame(points, margin=1.05)  # far enough: the bounding sphere fits
        self.target[2] = float(np.median(points[:, 2]))
        for _ in range(3):  # nearer points look bigger: fit, recentre, fit again
            self.distance = self._fitting_distance(points, border)
            pixels = self.project(points)
            left = 2.0 * self.shift_x
            middle = (pixels.min(axis=0) + pixels.max(axis=0)) / 2
            centre = np.array([(left + self.width) / 2, self.height / 2])
            dx, dy = middle - centre
            follow = self.follow
            self.pan(-dx, -dy)
            self.follow = follow
        self.distance = self._fitting_distance(points, border)

    def _fitting_distance(self, points: np.ndarray, border: float) -> float:
        """The least distance (at least 0.2 m) at which `points` stay inside the free part.

        The view's rotation does not depend on the distance, so a point's camera
        coordinates are q - (0, 0, d) with q fixed, and each bound of the picture asks
        for d at least some figure of q: the answer is the largest, in one pass over the
        points (a bisection of the same test when a bound cannot be met)."""
        left = 2.0 * self.shift_x / self.width  # the panel's share of the picture
        low_x = -1.0 + 2.0 * left + 2.0 * border * (1.0 - left)
        high = 1.0 - 2.0 * border
        shift = -2.0 * self.shift_x / self.width  # the lens shift (projection's [0, 2])
        if high <= 0 or high + shift <= 0 or low_x + shift >= 0:
            return self._bisected_distance(points, low_x, high)
        rotation = self.view()[:3, :3]
        q = (points - self.target) @ rotation.T  # camera coordinates at distance 0
        focal = 1.0 / np.tan(self.fov_y / 2)
        across = focal * self.height / self.width
        # w = d - q_z in front; ndc x = across q_x / w - shift, ndc y = focal q_y / w
        need = np.maximum.reduce([
            np.full(len(q), 1e-6),
            across * q[:, 0] / (high + shift),
            across * q[:, 0] / (low_x + shift),
            focal * np.abs(q[:, 1]) / high,
        ])  # fmt: skip
        return max(0.2, float(np.max(q[:, 2] + need)) * (1.0 + 1e-9))

    def _bisected_distance(self, points: np.ndarray, low_x: float, high: float) -> float:
        """`_fitting_distance` by bisection, for bounds no distance can meet."""

        def fits(distance: float) -> bool:
            self.distance = distance
            clip = np.hstack([points, np.ones((len(points), 1))]) @ self.view_projection().T
            if (clip[:, 3] <= 1e-6).any():
                return False
            ndc = clip[:, :2] / clip[:, 3:4]
            return bool(
                (ndc[:, 0] >= low_x).all() and (ndc[:, 0] <= high).all()
                and (np.abs(ndc[:, 1]) <= high).all()
            )  # fmt: skip

        near, far = 0.2, max(self.distance, 0.2)
        while not fits(far) and far < 1e4:
            far *= 2.0
        for _ in range(40):  # to a ten-thousandth of the distance: far below a pixel
            if far - near <= FIT_TOLERANCE * far:
                break
            middle = (near + far) / 2
            near, far = (near, middle) if fits(middle) else (middle, far)
        return far

    def ray(self, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
        """World ray (origin, unit direction) through pixel (x, y), origin bottom-left."""
        ndc = np.array([2 * x / self.width - 1, 2 * y / self.height - 1])
        inverse = np.linalg.inv(self.view_projection())
        near = inverse @ np.array([ndc[0], ndc[1], -1.0, 1.0])
        far = inverse @ np.array([ndc[0], ndc[1], 1.0, 1.0])
        near, far = near[:3] / near[3], far[:3] / far[3]
        direction = far - near
        return near, direction / np.linalg.norm(direction)

    def ground_point(self, x: float, y: float, height: float = 0.0) -> np.ndarray | None:
        """Where the ray through pixel (x, y) meets the plane z = height (None if it doesn't)."""
        origin, direction = self.ray(x, y)
        if abs(direction[2]) < 1e-9:
            return None
        t = (height - origin[2]) / direction[2]
        return origin + t * direction if t > 0 else None

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates (n, 2), origin bottom-left, of world points (n, 3)."""
        homogeneous = np.hstack([points, np.ones((len(points), 1))]) @ self.view_projection().T
        ndc = homogeneous[:, :2] / homogeneous[:, 3:4]
        pixels: np.ndarray = (ndc + 1) / 2 * [self.width, self.height]
        return pixels


def ray_sphere(
    origin: np.ndarray, direction: np.ndarray, centres: np.ndarray, radii: np.ndarray
) -> np.ndarray:
    """Distance along the ray to each sphere (inf where missed)."""
    to_centre = centres - origin
    along = to_centre @ direction
    closest_sq = np.einsum("ij,ij->i", to_centre, to_centre) - along**2
    inside = radii**2 - closest_sq
    hit = (inside >= 0) & (along > 0)
    return np.where(hit, along - np.sqrt(np.maximum(inside, 0)), np.inf)


def _sphere_directions() -> np.ndarray:
    """`_DIRECTIONS` unit vectors spread evenly over the sphere (a golden spiral)."""
    k = np.arange(_DIRECTIONS) + 0.5
    z = 1.0 - 2.0 * k / _DIRECTIONS
    angle = np.pi * (3.0 - np.sqrt(5.0)) * k
    ring = np.sqrt(1.0 - z**2)
    return np.stack([ring * np.cos(angle), ring * np.sin(angle), z], axis=1)
