#!/usr/bin/env python3
"""Turns bench_step's CSV into the per-kernel tables of docs/PERFORMANCE.md (markdown on stdout).

usage: step_table.py BENCH.csv [--ns]   (--ns: ns per node per step instead of µs per step)

Kernels are grouped by what they do in a step:
  geometry      triangle areas/normals, curvature, rounded-triangle spheres, cell area and volume
  bonds, bending, area, volume, external   the force terms (bending: hinge pass + gather)
  membrane (fused)  the four membrane terms in one edge pass (with the triangles on their wings) and a gather
                (kernels/membrane_forces.hpp; the default when all four are on)
  contact       plane contact per triangle, gather, sums
  solver set-up per step: bond directions, block-Jacobi blocks, implicit bending/tension/global stiffness,
                multigrid fine assembly and Galerkin products, smoother diagonal
  CG            per iteration: operator apply (friction, implicit terms), multigrid V-cycle, dots, updates
  integrator    Euler move, finiteness and bond checks, step control
  other         host work, copies and fences no kernel covers (step minus all kernels)
"""
import csv, sys
from collections import OrderedDict, defaultdict

GROUPS = [
    ("geometry", ("dcm::geometry::", "dcm::curvature::", "dcm::rounded_triangle::")),
    ("bonds", ("dcm::bonds::",)),
    ("bending", ("dcm::bending::",)),
    ("area", ("dcm::area::",)),
    ("volume", ("dcm::volume::",)),
    ("membrane (fused)", ("dcm::membrane::",)),
    ("contact", ("dcm::contact::",)),
    ("solver set-up", ("dcm::friction::bond_directions", "dcm::friction::block_jacobi",
                       "dcm::friction::substrate_triangles", "dcm::bending_stiffness::update",
                       "dcm::tension_stiffness::update", "dcm::global::gradients", "dcm::global::coefficients",
                       "dcm::model::implicit_bonds", "dcm::mg::assemble_fine", "dcm::mg::galerkin",
                       "dcm::bsr::invert_diagonal")),
    ("CG", ("dcm::cg::", "dcm::friction::apply", "dcm::friction::precondition", "dcm::bsr::", "dcm::mg::",
            "dcm::global::", "dcm::bending_stiffness::", "dcm::tension_stiffness::")),
    ("integrator", ("dcm::integrator::", "dcm::model::", "dcm::stepper::", "dcm::external::")),
]


def group_of(kernel):
    if kernel in ("step", "other"):
        return kernel
    for name, prefixes in GROUPS:  # first match wins: set-up names come before the CG prefixes
        if any(kernel.startswith(p) for p in prefixes):
            return name
    return "other"


def main():
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help") or sys.argv[1].startswith("-"):
        print(__doc__)
        return 0 if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help") else 2
    path = sys.argv[1]
    col = "ns_per_node" if "--ns" in sys.argv else "us_per_step"
    data = defaultdict(lambda: defaultdict(float))  # (scene, nodes) -> backend -> group -> value
    cg = {}
    backends = OrderedDict()
    for r in csv.DictReader(open(path)):
        backend = r["space"] if r["space"] == "Serial" else f'{r["space"]} {r["threads"]}'
        backends[backend] = True
        key = (r["scene"], int(r["nodes"]))
        data[key][(backend, group_of(r["kernel"]))] += float(r[col])
        cg[(key, backend)] = float(r["cg_iterations_per_step"])
    groups = [g for g, _ in GROUPS] + ["other", "step"]
    unit = "ns per node per step" if col == "ns_per_node" else "µs per step"
    for key in sorted(data, key=lambda k: (["stretch", "spread", "diagonal"].index(k[0]), k[1])):
        scene, nodes = key
        print(f"\n{scene}, {nodes} nodes ({unit}; CG iterations per step: "
              + ", ".join(f"{b} {cg[(key, b)]:.1f}" for b in backends if (key, b) in cg) + ")\n")
        print("| kernel group | " + " | ".join(backends) + " |")
        print("|---|" + "---|" * len(backends))
        for g in groups:
            vals = [data[key].get((b, g)) for b in backends]
            if all(v is None or abs(v) < 1e-12 for v in vals):
                continue
            fmt = "{:.1f}" if col == "ns_per_node" else "{:.0f}"
            cells = ["" if v is None else fmt.format(v) for v in vals]
            name = f"**{g}**" if g == "step" else g
            print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    sys.exit(main())
