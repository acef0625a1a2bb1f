"""`dump custom/vtk` and `dump mesh/vtk` write files that pyvista reads back with the right content."""
import pyvista as pv

from tsg_harness import run_lmp

SQUARE_STL = """solid plate
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 0.02 0 0
  vertex 0.02 0.02 0
 endloop
endfacet
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 0.02 0.02 0
  vertex 0 0.02 0
 endloop
endfacet
endsolid plate
"""

INPUT = """
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.001 0.021 -0.001 0.021 -0.001 0.02 units box
create_box 1 box
neighbor 0.0004 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5.0e6
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
fix plate all mesh/surface file plate.stl type 1
fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes plate
lattice sc 0.004
region fill block 0.002 0.018 0.002 0.018 0.004 0.012 units box
create_atoms 1 region fill
set group all diameter 0.002 density 2500
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
timestep 2.0e-6
thermo 100
dump particles all custom/vtk 100 particles_*.vtk id type x y z vx vy vz fx fy fz radius
dump surface all mesh/vtk 100 plate_*.vtk id
run 200
"""


def test_vtk_dumps_read_back(tmp_path):
    run = run_lmp(INPUT, tmp_path, files={"plate.stl": SQUARE_STL})
    run.assert_clean()
    natoms = int(run.thermo[-1]["Atoms"][-1])
    # sc lattice 4 mm: x, y at 4..16 mm (4 points), z at 4, 8, 12 mm (3 points)
    assert natoms == 4 * 4 * 3
    particles = pv.read(tmp_path / "particles_200.vtk")
    assert particles.n_points == natoms
    for name in ("id", "type", "v", "f", "radius"):
        assert name in particles.point_data, f"{name} missing from {list(particles.point_data)}"
    assert sorted(particles.point_data["id"].astype(int)) == list(range(1, natoms + 1))
    assert abs(particles.point_data["radius"] - 0.001).max() < 1e-12
    plate = pv.read(tmp_path / "plate_200.vtk")
    assert plate.n_cells == 2
    assert plate.n_points in (4, 6)
    assert abs(plate.area - 0.02 * 0.02) < 1e-6 * 0.02 * 0.02  # points are written in float32
    assert list(plate.cell_data["meshid"]) == [0, 1]
