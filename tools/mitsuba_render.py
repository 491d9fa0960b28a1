"""The Python half of tools/mitsuba-render: loads a scene with Mitsuba 3, renders it, writes the
film's EXR and reports the render time (after an optional warm-up render, so that the time of a
JIT variant excludes compilation)."""
import argparse
import json
import os
import time

import drjit as dr
import mitsuba as mi


def arguments():
    ap = argparse.ArgumentParser(prog="mitsuba-render", description=__doc__)
    ap.add_argument("scene")
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("--variant", default="scalar_spectral")
    ap.add_argument("--spp", type=int, default=0, help="samples per pixel (0: the scene's)")
    ap.add_argument("--threads", type=int, default=0, help="threads in all (0: every core)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--pass-spp", type=int, default=0,
                    help="render in passes of this many spp and average them (default: one pass "
                         "for scalar variants, 256 spp for JIT ones, which hold every path in memory)")
    ap.add_argument("--warmup", action="store_true", help="JIT variants: compile before timing")
    ap.add_argument("-D", action="append", default=[], metavar="NAME=VALUE")
    return ap.parse_args()


def main():
    args = arguments()
    mi.set_variant(args.variant)
    mi.set_log_level(mi.LogLevel.Warn)
    all_threads = dr.thread_count()
    if args.threads > 0:
        dr.set_thread_count(args.threads)
    scene = mi.load_file(args.scene, **dict(d.split("=", 1) for d in args.D))
    sensor = scene.sensors()[0]
    width, height = sensor.film().crop_size()
    spp = args.spp or sensor.sampler().sample_count()
    jit = not args.variant.startswith("scalar")
    pass_spp = args.pass_spp or (min(spp, 256) if jit else spp)
    if spp % pass_spp:
        raise SystemExit(f"--spp {spp} is not a multiple of --pass-spp {pass_spp}")

    def render(seed, samples):
        image = mi.render(scene, spp=samples, seed=seed)
        dr.eval(image)
        dr.sync_thread()
        return image

    if args.warmup and jit:
        render(args.seed + 7919, pass_spp)
    start = time.perf_counter()
    passes = spp // pass_spp
    image = render(args.seed, pass_spp)
    for i in range(1, passes):
        image = image + render(args.seed + i, pass_spp)
    if passes > 1:
        image = image / passes
    dr.eval(image)
    dr.sync_thread()
    seconds = time.perf_counter() - start

    # Mitsuba 3.9.1 deadlocks writing an EXR after set_thread_count(1): restore the thread pool.
    dr.set_thread_count(max(all_threads, 2))
    bitmap = sensor.film().bitmap() if passes == 1 else mi.Bitmap(image, sensor.film().bitmap().pixel_format())
    bitmap.write(args.output)
    result = {"scene": args.scene, "variant": args.variant, "spp": spp, "seed": args.seed,
              "threads": args.threads or all_threads, "width": width, "height": height,
              "render_s": seconds, "samples_per_s": width * height * spp / seconds,
              "mitsuba": mi.__version__, "output": args.output}
    print(f"{os.path.basename(args.scene)} {args.variant} {width}x{height} {spp} spp: "
          f"{seconds:.3f} s, {result['samples_per_s'] / 1e6:.3f} M samples/s -> {args.output}")
    print("RESULT " + json.dumps(result))


if __name__ == "__main__":
    main()
