"""Writes torus.off: the torus of examples/manufactured_torus.toml (center (0.5, 0.5, 0.5), major
radius 0.25, minor radius 0.1, about the z-axis) as 128 x 48 quadrilaterals of its angle chart, each
split in two triangles, oriented outward. Run: python3 make_torus.py"""
import math

major, minor, n_major, n_minor = 0.25, 0.1, 128, 48
vertices, faces = [], []
for i in range(n_major):
    a = 2 * math.pi * i / n_major
    for j in range(n_minor):
        b = 2 * math.pi * j / n_minor
        rho = major + minor * math.cos(b)
        vertices.append((0.5 + rho * math.cos(a), 0.5 + rho * math.sin(a), 0.5 + minor * math.sin(b)))
index = lambda i, j: (i % n_major) * n_minor + (j % n_minor)
for i in range(n_major):
    for j in range(n_minor):
        p, q, r, s = index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)
        faces += [(p, q, r), (p, r, s)]
with open("torus.off", "w") as out:
    out.write("OFF\n%d %d 0\n" % (len(vertices), len(faces)))
    out.writelines("%.9f %.9f %.9f\n" % v for v in vertices)
    out.writelines("3 %d %d %d\n" % f for f in faces)
