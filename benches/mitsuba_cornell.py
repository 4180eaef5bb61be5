#!/usr/bin/env python3
"""Path tracing on assets/scenes/cornell.ron, GI Studio against Mitsuba 3, side
by side in one run: samples per second, relMSE against the Cornell box's
reference, and efficiency 1/(relMSE x seconds), at 320x240 (the reference's
size) and the same samples per pixel. With --meshes, the same on
assets/scenes/cornell-mesh.ron, whose room is the OBJ files in
assets/meshes/, which Mitsuba reads too.

Mitsuba is not a dependency of the project: install it beside it, e.g.
    python3 -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba numpy
and for its LLVM variant Debian's libllvm19 (bookworm-backports), then
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
        /tmp/mi/bin/python benches/mitsuba_cornell.py target/release/gi-studio --spp 64 --runs 5

The scene is written for Mitsuba as a user would: its infinite planes as
large rectangles, the two emitting triangles as one rectangle, Lambert as
`diffuse`, the mirror as a `conductor` of reflectance 0.95, glass as a
`dielectric` of index 1.5, a box pixel filter, Mitsuba's `path` integrator
with its defaults. relMSE is GI Studio's (`gi-studio compare`), against the
reference GI Studio ships (4096 spp of its own path tracer): both images are
measured the same way.
"""

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mitsuba as mi

ROOT = Path(__file__).resolve().parent.parent
WIDTH, HEIGHT = 320, 240


def scene_dict(spp, meshes):
    T = mi.ScalarTransform4f

    def rgb(r, g, b):
        return {"type": "rgb", "value": [r, g, b]}

    def diffuse(r, g, b):
        return {"type": "diffuse", "reflectance": rgb(r, g, b)}

    def plane(to_world, bsdf):
        # A rectangle 200 units wide stands in for an infinite plane
        return {"type": "rectangle", "to_world": to_world @ T().scale(100.0), "bsdf": bsdf}

    def mesh(name, bsdf):
        # Each quad's own normal: the files hold none, and the room's walls share corners
        return {"type": "obj", "filename": str(ROOT / "assets/meshes" / name), "face_normals": True, "bsdf": bsdf}

    white, red, green = diffuse(0.75, 0.75, 0.75), diffuse(0.75, 0.15, 0.15), diffuse(0.15, 0.6, 0.15)
    if meshes:
        room = {
            "white": mesh("cornell-white.obj", white),
            "left": mesh("cornell-red.obj", red),
            "right": mesh("cornell-green.obj", green),
        }
    else:
        # A rectangle's normal is +z: each is turned to face the room
        room = {
            "floor": plane(T().rotate([1, 0, 0], -90.0), white),
            "ceiling": plane(T().translate([0.0, 2.0, 0.0]) @ T().rotate([1, 0, 0], 90.0), white),
            "back": plane(T().translate([0.0, 0.0, -1.0]), white),
            "left": plane(T().translate([-1.0, 0.0, 0.0]) @ T().rotate([0, 1, 0], 90.0), red),
            "right": plane(T().translate([1.0, 0.0, 0.0]) @ T().rotate([0, 1, 0], -90.0), green),
        }
    return room | {
        "type": "scene",
        "integrator": {"type": "path"},
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "y",
            "to_world": T().look_at(origin=[0.0, 1.0, 3.4], target=[0.0, 1.0, 0.0], up=[0.0, 1.0, 0.0]),
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "mirror": {
            "type": "sphere",
            "center": [-0.45, 0.35, -0.35],
            "radius": 0.35,
            "bsdf": {"type": "conductor", "material": "none", "specular_reflectance": rgb(0.95, 0.95, 0.95)},
        },
        "glass": {
            "type": "sphere",
            "center": [0.45, 0.35, 0.2],
            "radius": 0.35,
            "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
        },
        "panel": {
            "type": "rectangle",
            "to_world": T().translate([0.0, 1.99, 0.0]) @ T().rotate([1, 0, 0], 90.0) @ T().scale(0.3),
            "bsdf": {"type": "diffuse", "reflectance": rgb(0.0, 0.0, 0.0)},
            "emitter": {"type": "area", "radiance": rgb(15.0, 15.0, 15.0)},
        },
    }


def rel_mse(studio, image, reference):
    out = subprocess.run([studio, "compare", str(reference), str(image)], capture_output=True, text=True, check=True)
    return float(re.search(r"relMSE ([0-9.eE+-]+)", out.stdout).group(1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("studio", help="the gi-studio binary (a release build)")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--runs", type=int, default=5, help="interleaved runs of each")
    parser.add_argument("--variant", default="llvm_ad_rgb")
    parser.add_argument("--meshes", action="store_true", help="the Cornell box whose room is OBJ meshes")
    args = parser.parse_args()
    mi.set_variant(args.variant)
    import drjit as dr

    name = "cornell-mesh" if args.meshes else "cornell"
    scene_file = ROOT / f"assets/scenes/{name}.ron"
    reference = ROOT / f"assets/references/{name}.exr"
    scene = mi.load_dict(scene_dict(args.spp, args.meshes))
    # Mitsuba compiles its kernels on the first render: not counted
    dr.eval(mi.render(scene, spp=args.spp))
    dr.sync_thread()
    figures = {"GI Studio": [], "Mitsuba": []}
    with tempfile.TemporaryDirectory() as folder:
        for run in range(args.runs):
            ours = Path(folder) / f"ours-{run}.exr"
            out = subprocess.run(
                [args.studio, "render", str(scene_file), "--algo", "path", "--spp", str(args.spp),
                 "--width", str(WIDTH), "--height", str(HEIGHT), "--seed", str(run), "-o", str(ours), "--force"],
                capture_output=True, text=True, check=True,
            )
            seconds = float(re.search(r"spp in ([0-9.]+) s", out.stdout + out.stderr).group(1))
            figures["GI Studio"].append((seconds, rel_mse(args.studio, ours, reference)))

            theirs = Path(folder) / f"mitsuba-{run}.exr"
            start = time.perf_counter()
            image = mi.render(scene, spp=args.spp, seed=run)
            # The LLVM variant launches its kernels asynchronously
            dr.eval(image)
            dr.sync_thread()
            seconds = time.perf_counter() - start
            mi.Bitmap(image).write(str(theirs))
            figures["Mitsuba"].append((seconds, rel_mse(args.studio, theirs, reference)))

    samples = WIDTH * HEIGHT * args.spp
    print(f"{name}.ron, path tracing, {WIDTH}x{HEIGHT}, {args.spp} spp, medians of {args.runs} interleaved runs")
    print(f"{'':10} {'seconds':>8} {'M samples/s':>12} {'relMSE':>9} {'efficiency':>11}")
    efficiency = {}
    for name, runs in figures.items():
        seconds = statistics.median(s for s, _ in runs)
        error = statistics.median(e for _, e in runs)
        efficiency[name] = statistics.median(1.0 / (s * e) for s, e in runs)
        print(f"{name:10} {seconds:8.3f} {samples / seconds / 1e6:12.2f} {error:9.4f} {efficiency[name]:11.1f}")
    print(f"efficiency ratio, GI Studio / Mitsuba: {efficiency['GI Studio'] / efficiency['Mitsuba']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
