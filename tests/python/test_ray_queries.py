"""Ray queries: `scene.ray_intersect` and `scene.ray_test` against the closed forms of a sphere
and a rectangle, the single-ray `Ray3f` form against the arrays, and the hits against the
renderer's own (the `aov` integrator's shape index, normal and position per pixel), and
other Python threads running while a batch is traced."""

import math
import threading
import time

import numpy as np
import pytest

import prism_renderer as pr

CENTER, RADIUS = np.array([0.5, -0.25, 1.0]), 1.5
# The rectangle [-1, 1]² of z = 0 scaled by (2, 3) and moved to z = -4: x in [-2, 2], y in
# [-3, 3], its normal +z.
HALF = np.array([2.0, 3.0])
PLANE_Z = -4.0


def _scene(**sensor) -> pr.Scene:
    return pr.load_dict({
        "type": "scene",
        "ball": {"type": "sphere", "center": CENTER.tolist(), "radius": RADIUS},
        "wall": {
            "type": "rectangle",
            "to_world": pr.Transform().translate([0, 0, PLANE_Z]).scale([HALF[0], HALF[1], 1]),
        },
        "sensor": {
            "type": "perspective",
            "fov": 60,
            "fov_axis": "x",
            "to_world": pr.Transform().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": 16, "height": 16, "rfilter": {"type": "box"}},
            **sensor,
        },
    })


@pytest.fixture(scope="module")
def scene() -> pr.Scene:
    return _scene()


def _sphere_t(o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The nearest positive root of |o + t d − c|² = r², in float64; inf where none."""
    oc = o - CENTER
    a = (d * d).sum(1)
    b = 2 * (oc * d).sum(1)
    c = (oc * oc).sum(1) - RADIUS**2
    disc = b * b - 4 * a * c
    root = np.sqrt(np.maximum(disc, 0))
    near, far = (-b - root) / (2 * a), (-b + root) / (2 * a)
    t = np.where(near > 0, near, far)
    return np.where((disc >= 0) & (t > 0), t, np.inf)


def test_rays_against_the_sphere_in_closed_form(scene):
    rng = np.random.default_rng(1)
    n = 2000
    # From outside the sphere, towards points near it (some miss), and from inside it.
    outside = CENTER + rng.normal(size=(n, 3)) * 4
    outside = outside[np.linalg.norm(outside - CENTER, axis=1) > RADIUS * 1.05]
    targets = CENTER + rng.normal(size=(len(outside), 3)) * RADIUS
    inside = CENTER + rng.uniform(-0.5, 0.5, size=(200, 3))
    origins = np.concatenate([outside, inside])
    directions = np.concatenate([targets - outside, rng.normal(size=(200, 3))])
    directions *= rng.uniform(0.5, 2.0, size=(len(origins), 1))  # not of unit length
    si = scene.ray_intersect(origins, directions)
    expected = _sphere_t(origins, directions)
    # Rays that miss the sphere may meet the wall: keep those whose sphere hit is first.
    ball = si.shape == 0
    assert ball.sum() > 1000 and (~ball).sum() > 100
    assert np.array_equal(ball, np.isfinite(expected) & (si.t >= expected * (1 - 1e-4)))
    np.testing.assert_allclose(si.t[ball], expected[ball], rtol=2e-5)
    p = origins[ball] + expected[ball, None] * directions[ball]
    np.testing.assert_allclose(si.p[ball], p, atol=2e-5 * 6)
    outward = (p - CENTER) / RADIUS
    np.testing.assert_allclose(si.n[ball], outward, atol=1e-4)
    np.testing.assert_allclose(si.sh_n[ball], outward, atol=1e-4)
    # Mitsuba's parametrisation: (φ/2π, θ/π) about the sphere's z axis.
    phi = np.mod(np.arctan2(outward[:, 1], outward[:, 0]), 2 * math.pi)
    theta = np.arccos(np.clip(outward[:, 2], -1, 1))
    u_error = np.abs(si.uv[ball, 0] - phi / (2 * math.pi))
    assert (np.minimum(u_error, 1 - u_error) < 1e-4).all()
    np.testing.assert_allclose(si.uv[ball, 1], theta / math.pi, atol=1e-4)
    assert (si.prim_index[ball] == 0).all()
    assert si.is_valid().dtype == bool and np.array_equal(si.is_valid(), si.shape >= 0)
    missed = ~si.is_valid()
    assert missed.any() and np.isinf(si.t[missed]).all() and (si.prim_index[missed] == -1).all()


def test_rays_against_the_rectangle_in_closed_form(scene):
    rng = np.random.default_rng(2)
    n = 1000
    # Straight down the z axis from beside the sphere, towards z = PLANE_Z.
    xy = rng.uniform(-2.5, 2.5, size=(n, 2)) * [1, 1.4]
    xy = xy[np.hypot(xy[:, 0] - CENTER[0], xy[:, 1] - CENTER[1]) > RADIUS * 1.01]
    origins = np.column_stack([xy, np.full(len(xy), 3.0)])
    directions = np.tile([0.0, 0.0, -2.0], (len(xy), 1))
    si = scene.ray_intersect(origins, directions)
    inside = (np.abs(xy) < HALF).all(1)
    assert inside.sum() > 200 and (~inside).sum() > 100
    assert np.array_equal(si.shape == 1, inside) and np.array_equal(si.is_valid(), inside)
    np.testing.assert_allclose(si.t[inside], (3.0 - PLANE_Z) / 2, rtol=1e-6)
    np.testing.assert_allclose(si.p[inside, :2], xy[inside], atol=1e-5)
    np.testing.assert_allclose(si.p[inside, 2], PLANE_Z, atol=1e-5)
    assert np.array_equal(si.n[inside], np.tile([0.0, 0.0, 1.0], (inside.sum(), 1)))
    # Mitsuba's rectangle: uv = ((x + 1)/2, (y + 1)/2) in its own [-1, 1]², over two triangles.
    np.testing.assert_allclose(si.uv[inside], (xy[inside] / HALF + 1) / 2, atol=1e-5)
    assert set(np.unique(si.prim_index[inside])) == {0, 1}
    # Shadow rays: blocked exactly when the wall lies before tmax.
    t_wall = (3.0 - PLANE_Z) / 2
    assert np.array_equal(scene.ray_test(origins, directions), inside)
    assert not scene.ray_test(origins, directions, tmax=t_wall * 0.999).any()
    tmax = np.where(np.arange(len(xy)) % 2 == 0, t_wall * 1.001, t_wall * 0.999)
    assert np.array_equal(scene.ray_test(origins, directions, tmax), inside & (tmax > t_wall))


def test_one_ray3f_is_its_row_of_the_arrays(scene):
    ray = pr.Ray3f([0.1, 0.2, 5.0], [0.0, 0.0, -1.0])
    assert ray(2.0) == pytest.approx([0.1, 0.2, 3.0])
    one = scene.ray_intersect(ray)
    rows = scene.ray_intersect(np.array([ray.o]), np.array([ray.d]))
    for name in ("t", "p", "n", "sh_n", "uv", "shape", "prim_index"):
        assert np.array_equal(getattr(one, name), getattr(rows, name)[0]), name
    assert one.is_valid() and one.shape == 0
    assert one.t == pytest.approx(_sphere_t(np.array([ray.o]), np.array([ray.d]))[0], rel=1e-5)
    assert scene.ray_test(ray)
    short = pr.Ray3f(ray.o, ray.d, maxt=0.5)
    assert not scene.ray_test(short) and not scene.ray_intersect(short).is_valid()
    with pytest.raises(ValueError, match="alone"):
        scene.ray_intersect(ray, np.zeros((1, 3)))
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        scene.ray_intersect(np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(ValueError, match="2 origins but 3 directions"):
        scene.ray_intersect(np.zeros((2, 3)), np.zeros((3, 3)))


def test_the_hits_are_the_renderers():
    """The `aov` integrator's per-pixel mean shape index, geometric normal and position (16
    samples uniformly over each pixel, box filter) against the rays through the pixel
    centres: equal where every sample hit one shape, the position within five standard
    errors of the spread of the positions over a pixel."""
    spp, size, fov = 16, 16, 40.0
    scene = pr.load_dict({
        "type": "scene",
        "integrator": {"type": "aov", "aovs": "si:shape_index,nn:geo_normal,pp:position"},
        "ball": {"type": "sphere", "center": [0.5, -0.25, 1.0], "radius": 1.0},
        # Behind the ball and filling the view.
        "wall": {"type": "rectangle",
                 "to_world": pr.Transform().translate([0, 0, -4]).scale([6, 6, 1])},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "x",
            "to_world": pr.Transform().look_at(origin=[0, 0, 8], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    })
    image = pr.render(scene, seed=4, progress=False)
    # Rays through the pixel centres: the camera looks down −z from z = 8, image x along +x
    # and image y along −y.
    centre = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(centre, centre)
    tan = math.tan(math.radians(fov / 2))
    directions = np.stack([x * tan, -y * tan, -np.ones_like(x)], -1).reshape(-1, 3)
    origins = np.tile([0.0, 0.0, 8.0], (size * size, 1))
    si = scene.ray_intersect(origins, directions)
    assert si.is_valid().all()
    shape = si.shape.reshape(size, size)
    index = image.aovs["si.I"]
    whole = (index == 0) | (index == 1)
    assert (whole & (index == 0)).sum() > 20 and (whole & (index == 1)).sum() > 100
    assert np.array_equal(shape[whole], index[whole].astype(int))
    normal = np.stack([image.aovs[f"nn.{c}"] for c in "XYZ"], -1)
    wall = whole & (index == 1)
    np.testing.assert_allclose(normal[wall], si.n.reshape(size, size, 3)[wall], atol=1e-6)
    # Over a pixel the position spreads by about its change from one pixel to the next, so
    # the mean of 16 uniform samples lies within 5 σ = 5 · step / √12 / √16 of the centre's.
    position = np.stack([image.aovs[f"pp.{c}"] for c in "XYZ"], -1)
    centres = si.p.reshape(size, size, 3)
    step = np.maximum(np.abs(np.gradient(centres, axis=0)), np.abs(np.gradient(centres, axis=1)))
    tolerance = 5 * np.sqrt(2) * step / math.sqrt(12) / math.sqrt(spp) + 1e-5
    assert (np.abs(position - centres)[wall] <= tolerance[wall]).all()


def test_other_python_threads_run_while_rays_are_traced(cornell):
    rng = np.random.default_rng(3)
    n = 400_000
    origins = np.tile([278.0, 273.0, -800.0], (n, 1))
    directions = np.column_stack([rng.normal(0, 0.2, (n, 2)), np.ones(n)])
    counts = []
    stop = threading.Event()

    def count():
        k = 0
        while not stop.is_set():
            k += 1
            if k % 1000 == 0:
                counts.append(time.monotonic())

    worker = threading.Thread(target=count)
    worker.start()
    try:
        start = time.monotonic()
        si = cornell.ray_intersect(origins, directions)
        end = time.monotonic()
    finally:
        stop.set()
        worker.join()
    assert si.is_valid().mean() > 0.5
    # The batch is the same traced again (each ray's answer is its own).
    assert np.array_equal(si.t, cornell.ray_intersect(origins, directions).t)
    during = [t for t in counts if start < t < end]
    # A thread held off by the GIL while the rays are traced would count nothing then.
    assert len(during) > 100
