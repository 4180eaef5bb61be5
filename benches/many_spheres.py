#!/usr/bin/env python3
"""A scene of many small spheres on a floor under a sun and a ball light,
for timing what grows with the object count (issue: 100,000 spheres made
photon mapping take 47 s at 32×24).

    python3 benches/many_spheres.py 100000 > /tmp/many.ron
    for algo in path photon sppm bdpt; do
      /usr/bin/time -f "$algo %e s" gi-studio render /tmp/many.ron --algo $algo \
        --width 32 --height 24 --spp 1 -o /tmp/many.exr --force
    done
"""
import random
import sys

count = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
random.seed(7)
side = max(1, int(count ** 0.5))
print("(")
print("    camera: (position: (0.0, 30.0, 60.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov_y_degrees: 45.0),")
print("    background: (0.0, 0.0, 0.0),")
print("    ambient: (0.0, 0.0, 0.0),")
print("    settings: (width: 32, height: 24, exposure: 0.0),")
print("    materials: [")
print('        (name: "clay", model: Lambert(albedo: (0.7, 0.6, 0.5))),')
print('        (name: "glass", model: Glass(ior: 1.5, tint: (1.0, 1.0, 1.0))),')
print('        (name: "lamp", model: Emissive(radiance: (20.0, 20.0, 20.0))),')
print("    ],")
print("    objects: [")
print('        (name: "floor", shape: Plane(point: (0.0, 0.0, 0.0), normal: (0.0, 1.0, 0.0)), material: "clay"),')
print('        (name: "lamp", shape: Sphere(center: (0.0, 25.0, 0.0), radius: 3.0), material: "lamp"),')
for k in range(count):
    x = (k % side - side / 2) * 40.0 / side + random.uniform(-0.05, 0.05)
    z = (k // side - side / 2) * 40.0 / side + random.uniform(-0.05, 0.05)
    r = 0.3 * 40.0 / side
    material = "glass" if k % 50 == 0 else "clay"
    print(f'        (name: "ball {k}", shape: Sphere(center: ({x:.4f}, {r:.4f}, {z:.4f}), radius: {r:.4f}), material: "{material}"),')
print("    ],")
print('    lights: [(name: "sun", kind: Directional(direction: (-1.0, -2.0, -0.5)), color: (1.0, 1.0, 0.9), intensity: 1.0)],')
print(")")
