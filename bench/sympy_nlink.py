#!/usr/bin/env python3
"""Reference: sympy.physics.mechanics' LagrangesMethod on the same N-link pendulum (point masses on
massless rods), timed from building the Lagrangian to the equations of motion, i.e. the work qdot's
derivation does. Prints one markdown row per n. Usage: sympy_nlink.py N [N ...]"""
import sys
import time

from sympy import cos, sin, symbols
from sympy.physics.mechanics import (LagrangesMethod, Lagrangian, Particle, Point, ReferenceFrame,
                                     dynamicsymbols)


def derive(n):
    q = dynamicsymbols(f"q:{n}")
    m, l, g = symbols("m l g")
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    particles, prev = [], O
    for i in range(n):
        P = prev.locatenew(f"P{i}", l * sin(q[i]) * N.x - l * cos(q[i]) * N.y)
        P.set_vel(N, P.pos_from(O).dt(N))
        pa = Particle(f"Pa{i}", P, m)
        pa.potential_energy = m * g * P.pos_from(O).dot(N.y)
        particles.append(pa)
        prev = P
    L = Lagrangian(N, *particles)
    LM = LagrangesMethod(L, q)
    return LM.form_lagranges_equations()


for arg in sys.argv[1:]:
    n = int(arg)
    t0 = time.perf_counter()
    derive(n)
    print(f"| {n} | {1e3 * (time.perf_counter() - t0):.1f} |", flush=True)
