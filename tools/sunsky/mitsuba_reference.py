"""Reference radiance of Mitsuba 3's `sunsky` emitter (scalar_spectral), printed as Rust
arrays for tests/integration/lights/sunsky.rs. Run once with Mitsuba 3.9.1's Python:

    ~/.cache/prism/mitsuba-3.9.1/bin/python tools/sunsky/mitsuba_reference.py
"""
import math

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_spectral")

WAVELENGTHS = [[360.0, 415.5, 550.0, 633.3], [500.0, 680.0, 719.0, 750.0]]


def norm(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def rotate(axis_angle_deg, v):
    # Rodrigues rotation about a unit axis.
    axis, deg = axis_angle_deg
    k = norm(axis)
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    d = sum(k[i] * v[i] for i in range(3))
    cr = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]]
    return [v[i] * c + cr[i] * s + k[i] * d * (1 - c) for i in range(3)]


def directions_around(sun, aperture_deg, to_world):
    """World directions: the zenith, near the horizon, opposite the sun, 5 degrees from the
    sun, the sun's centre, and 0.8 of the disc's radius from it (`to_world` maps the emitter's
    +z-up frame to the world)."""
    sun = norm(sun)
    world = lambda v: list(to_world @ mi.ScalarVector3f(v))
    local_sun = list(to_world.inverse() @ mi.ScalarVector3f(sun))
    # A vector orthogonal to the sun.
    helper = [0.0, 0.0, 1.0] if abs(sun[2]) < 0.9 else [1.0, 0.0, 0.0]
    ortho = norm([sun[1] * helper[2] - sun[2] * helper[1],
                  sun[2] * helper[0] - sun[0] * helper[2],
                  sun[0] * helper[1] - sun[1] * helper[0]])
    tilt = lambda deg: [math.cos(math.radians(deg)) * sun[i] + math.sin(math.radians(deg)) * ortho[i] for i in range(3)]
    return [
        world([0.0, 0.0, 1.0]),
        world(norm([0.6, -0.8, 0.02])),
        world(norm([-local_sun[0], -local_sun[1], abs(local_sun[2]) + 0.3])),
        tilt(5.0),
        sun,
        tilt(0.8 * 0.5 * aperture_deg),
    ]


CASES = [
    ("default", {"sun_direction": [0.3, 0.2, 0.8]}, None),
    ("low_sun", {"sun_direction": [1.0, 0.5, 0.15], "turbidity": 6.5, "albedo": 0.7}, None),
    ("complex", {"sun_direction": [0.0, -0.6, 0.5], "turbidity": 2.3, "complex_sun": True,
                 "sun_aperture": 2.0, "sun_scale": 0.5, "sky_scale": 2.0}, None),
    ("rgb_albedo", {"sun_direction": [-0.4, 0.1, 0.6], "turbidity": 9.2,
                    "albedo": {"type": "rgb", "value": [0.8, 0.3, 0.1]}}, None),
    ("y_up", {"sun_direction": [0.2, 0.9, -0.3],
              "to_world": mi.ScalarTransform4f().rotate([1, 0, 0], -90)}, None),
    ("date", {"latitude": 48.2, "longitude": 16.37, "timezone": 1, "year": 2021, "month": 3,
              "day": 21, "hour": 10.5, "minute": 20, "second": 30}, None),
]


def main():
    for name, props, _ in CASES:
        emitter = mi.load_dict(dict({"type": "sunsky"}, **props))
        params = mi.traverse(emitter)
        sun = [params["sun_direction"][i] for i in range(3)]
        aperture = props.get("sun_aperture", 0.5358)
        shown = {k: v for k, v in props.items() if k != "to_world"}
        if "to_world" in props:
            shown["to_world"] = "rotate x by -90 degrees"
        print(f"/// `{name}`: {shown}; Mitsuba's sun_direction {sun}.")
        print(f"const {name.upper()}: &[Probe] = &[")
        si = mi.SurfaceInteraction3f()
        to_world = props.get("to_world", mi.ScalarTransform4f())
        for d in directions_around(sun, aperture, to_world):
            for lam in WAVELENGTHS:
                si.wi = mi.Vector3f(-d[0], -d[1], -d[2])
                si.wavelengths = mi.Spectrum(lam)
                value = emitter.eval(si)
                f32 = lambda x: np.format_float_scientific(np.float32(x), unique=True, trim="0", exp_digits=1)
                print(f"    ([{f32(d[0])}, {f32(d[1])}, {f32(d[2])}], {lam}, "
                      f"[{', '.join(f32(value[i]) for i in range(4))}]),")
        print("];")


main()
