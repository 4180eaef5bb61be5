#!/usr/bin/env python3
"""Mitsuba 3's rough conductor on a grid of directions, for tests/mitsuba_bsdf.rs.

Writes tests/data/mitsuba_roughconductor.csv: for each surface (α_u, α_v,
η and k per RGB channel) and each pair of directions in the surface's frame
(a named metal or `custom`, z the normal; `wo` toward the viewer, Mitsuba's si.wi; `wi` toward the
light, Mitsuba's wo), Mitsuba's `eval` (f · cos θi) and `pdf`, from its
`roughconductor` with GGX and visible-normal sampling, variant scalar_rgb.
The Rust test holds GI Studio's BSDF to these values within 1e-3 relative.

    python3 -m venv ../venv-mitsuba && ../venv-mitsuba/bin/pip install mitsuba
    ../venv-mitsuba/bin/python tools/mitsuba_bsdf.py
"""
import math
import os

import mitsuba as mi

mi.set_variant("scalar_rgb")

# (α_u, α_v, metal): named metals as Mitsuba's RGB variant reduces them,
# and an index written out
SURFACES = [
    (0.05, 0.05, "Au"),
    (0.3, 0.3, "Al"),
    (1.0, 1.0, "Cu"),
    (0.1, 0.5, "Ag"),
    (0.4, 0.15, ((1.5, 0.9, 0.4), (2.0, 3.5, 5.0))),
]


def direction(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))


def main():
    out = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "mitsuba_roughconductor.csv")
    rows = ["metal,alpha_u,alpha_v,eta_r,eta_g,eta_b,k_r,k_g,k_b,wo_x,wo_y,wo_z,wi_x,wi_y,wi_z,f_r,f_g,f_b,pdf"]
    ctx = mi.BSDFContext()
    for alpha_u, alpha_v, metal in SURFACES:
        spec = {"type": "roughconductor", "distribution": "ggx", "alpha_u": alpha_u, "alpha_v": alpha_v, "sample_visible": True}
        if isinstance(metal, str):
            spec["material"] = metal
        else:
            spec["eta"] = {"type": "rgb", "value": metal[0]}
            spec["k"] = {"type": "rgb", "value": metal[1]}
        bsdf = mi.load_dict(spec)
        params = mi.traverse(bsdf)
        eta, k = params["eta.value"], params["k.value"]
        for theta_o in (0.0, 25.0, 55.0, 80.0):
            for phi_o in (0.0, 130.0):
                wo = direction(theta_o, phi_o)
                si = mi.SurfaceInteraction3f()
                si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
                si.wi = mi.Vector3f(*wo)
                for theta_i in (5.0, 30.0, 50.0, 70.0, 85.0):
                    for phi_i in (0.0, 60.0, 170.0, 200.0, 310.0):
                        wi = direction(theta_i, phi_i)
                        value = bsdf.eval(ctx, si, mi.Vector3f(*wi))
                        pdf = bsdf.pdf(ctx, si, mi.Vector3f(*wi))
                        numbers = [alpha_u, alpha_v, *eta, *k, *wo, *wi, value[0], value[1], value[2], pdf]
                        name = metal if isinstance(metal, str) else "custom"
                        rows.append(",".join([name] + [f"{float(x):.9g}" for x in numbers]))
    with open(out, "w") as f:
        f.write("\n".join(rows) + "\n")
    print(f"{len(rows) - 1} rows written to {os.path.normpath(out)}")


if __name__ == "__main__":
    main()
