"""What tools/bench-vs-mitsuba and tools/reconstruction-study share: running commands, building
Prism, rendering with Prism and with Mitsuba 3 (through tools/mitsuba-render), relMSE and the
z-test of `prism compare`, and the mean over seeds of one renderer's time and error.

Standard library only; the tools put this folder on sys.path and `import benchlib`.
"""
import json
import math
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MITSUBA = os.path.join(HERE, "tools", "mitsuba-render")


def run(command, **kwargs):
    result = subprocess.run(command, capture_output=True, text=True, cwd=HERE, **kwargs)
    if result.returncode != 0:
        sys.exit(f"failed: {' '.join(command)}\n{result.stdout}\n{result.stderr}")
    return result


def build(features=False):
    """Builds Prism with cargo (with --features embree in target/embree) and returns the binary."""
    target = os.path.join(HERE, "target", "embree" if features else "")
    command = ["cargo", "build", "--release", "--quiet"]
    if features:
        command += ["--features", "embree", "--target-dir", target]
    run(command)
    return os.path.join(target if features else os.path.join(HERE, "target"), "release", "prism")


def compare(prism, test, reference):
    """What `prism compare TEST REFERENCE` prints."""
    return run([prism, "compare", test, reference]).stdout


def rel_mse(prism, test, reference, text=None):
    """The relMSE over R, G, B of `prism compare` (its row 'all': MSE, then relMSE); `text` is
    the output of an earlier compare() of the same images, to read instead of running it again."""
    for line in (text if text is not None else compare(prism, test, reference)).splitlines():
        fields = line.split()
        if fields and fields[0] == "all":
            return float(fields[-1])
    sys.exit(f"no 'all' row in the output of prism compare {test} {reference}")


Z_TEST = re.compile(
    r"z-test of Y over (?P<pixels>\d+) pixels: chi² (?P<chi2>[0-9.eE+-]+|inf|NaN) "
    r"\(p = (?P<p_value>[0-9.eE+-]+|NaN)\), max \|z\| (?P<max_z>[0-9.eE+-]+|inf|NaN) "
    r"\(Bonferroni p = (?P<max_z_p_value>[0-9.eE+-]+|NaN)\), (?P<beyond_three>[0-9.eE+-]+|NaN) % "
    r"beyond \|z\| = 3 \(0\.27 % expected\): (?P<verdict>(?:NOT )?consistent with noise)")


def z_test(text):
    """The z-test line of `prism compare`'s output as a dict (pixels, chi2, p_value, max_z,
    max_z_p_value, beyond_three in percent, consistent, verdict; max_z None where it is
    infinite), or None when it printed none (the test image has no `variance.Y` channel, as
    Mitsuba's have not)."""
    match = Z_TEST.search(text)
    if not match:
        return None
    z = {k: float(v) for k, v in match.groupdict().items() if k not in ("pixels", "verdict")}
    if z["max_z"] == float("inf"):
        # A pixel differs where both variances are 0; `prism compare` then prints a Bonferroni p
        # of 1, which is wrong (its verdict rests on the chi-square sum alone): no p here.
        z["max_z"] = z["max_z_p_value"] = None
    z["pixels"] = int(match["pixels"])
    z["verdict"] = match["verdict"]
    z["consistent"] = not match["verdict"].startswith("NOT")
    return z


def prism_render(binary, scene, defines, spp, threads, output, seed, extra=()):
    """Renders with Prism; returns (seconds, samples per second) from its summary line, the
    seconds as samples / rate (the line rounds them to 0.01 s, its rate to four digits)."""
    command = [binary, "render", scene, "-o", output, "--spp", str(spp), "--threads", str(threads),
               "--seed", str(seed)] + [a for d in defines for a in ("-D", d)] + list(extra)
    line = run(command).stderr.strip().splitlines()[-1]
    match = re.search(r"\((\d+)×(\d+), (\d+) spp[^)]*\) in ([0-9.]+) s: ([0-9.]+) M samples/s", line)
    if not match:
        sys.exit(f"could not read Prism's summary line: {line}")
    width, height, samples, seconds, rate = (float(g) for g in match.groups())
    rate *= 1e6
    return (width * height * samples / rate if rate > 0 else seconds), rate


def mitsuba_render(variant, scene, defines, spp, threads, output, seed):
    """Renders with Mitsuba 3 (JIT variants timed after a warm-up render); returns (seconds,
    samples per second)."""
    command = [MITSUBA, scene, "-o", output, "--variant", variant,
               "--spp", str(spp), "--threads", str(threads), "--seed", str(seed)]
    command += [a for d in defines for a in ("-D", d)]
    if variant.startswith("llvm"):
        command.append("--warmup")
    line = next(l for l in run(command).stdout.splitlines() if l.startswith("RESULT "))
    result = json.loads(line[len("RESULT "):])
    return result["render_s"], result["samples_per_s"]


def measure(prism, render, reference, seeds, output):
    """Renders with `render(path, seed)` (returning seconds and samples/s) for the seeds 2, 3,
    ..., 1 + `seeds`, to `output(seed)`, and measures each image's relMSE against `reference`.
    Returns the means (seconds, and samples/s as all samples over all seconds), the range of
    relMSE, efficiency = 1 / (relMSE x seconds), and the images with their compare() outputs."""
    seconds, samples, errors, images = [], [], [], []
    for seed in range(2, 2 + seeds):
        path = output(seed)
        elapsed, rate = render(path, seed)
        text = compare(prism, path, reference)
        seconds.append(elapsed)
        samples.append(elapsed * rate)
        errors.append(rel_mse(prism, path, reference, text))
        images.append((path, text))
    mean_seconds = sum(seconds) / len(seconds)
    error = sum(errors) / len(errors)
    # The standard error of the mean relMSE over seeds (None for one seed): on scenes decided by
    # rare fireflies it says whether two renderers' means differ by more than luck.
    error_se = (math.sqrt(sum((e - error) ** 2 for e in errors) / (seeds - 1) / seeds)
                if seeds > 1 else None)
    row = {"seeds": seeds, "seconds": mean_seconds,
           "samples_per_second": sum(samples) / len(samples) / mean_seconds,
           "rel_mse": error, "rel_mse_min": min(errors), "rel_mse_max": max(errors),
           "rel_mse_standard_error": error_se, "rel_mse_per_seed": errors,
           "efficiency": 1.0 / (error * mean_seconds)}
    return row, images


def summary(name, label, row):
    """One line of a measured renderer: samples/s, relMSE (with its standard error and range over
    seeds), efficiency."""
    spread = (f" ± {row['rel_mse_standard_error']:.1e} ({row['rel_mse_min']:.2e}-{row['rel_mse_max']:.2e})"
              if row["seeds"] > 1 else "")
    return (f"{name:<18} {label:<26} {row['samples_per_second'] / 1e6:7.3f} Msamples/s  "
            f"relMSE {row['rel_mse']:.3e}{spread}  efficiency {row['efficiency']:9.2f}")


def append_json(path, row):
    if path:
        with open(path, "a") as f:
            f.write(json.dumps(row) + "\n")
