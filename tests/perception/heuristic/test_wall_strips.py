"""A plain wall taken for fronts: a strip along a plane's top or bottom edge (a skirting, a plinth, a cornice)
is not what cuts a front out of a plane, and a plane with nothing behind it is no piece standing in the
room. Hand-made orthophotos and meshes for the two rules the quarter-decimated TSDF wardrobe traced to."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import HeuristicConfig, RoomWallConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.geometry import concat_meshes
from react3d_core.perception.heuristic.front_cells import Cell, split_cells
from react3d_core.perception.heuristic.image_fronts import is_tiled, stands_in_room
from react3d_core.perception.heuristic.planes import Plane, share_behind
from tests.perception.heuristic.flat_orthos import flat_ortho


def _quad(x0: float, x1: float, y: float, z0: float, z1: float, towards_room: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """A rectangle in the plane y = ``y``, facing -y (the room) or +y."""
    v = np.array([[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]], float)
    f = np.array([[0, 1, 2], [0, 2, 3]]) if towards_room else np.array([[0, 2, 1], [0, 3, 2]])
    return v, f


def _floor(x0: float, x1: float, y0: float, y1: float) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x0, y0, 0.0], [x1, y0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0]])
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def test_share_behind_by_hand() -> None:
    """A room: floor x -1..5, y -1..3 (24 m²; its two triangles' centroids at y 0.33 and 1.67), the outer
    wall y = 3 (6 x 2.5 = 15 m²), a cabinet front at y = 2.4 (0.6 x 0.75 = 0.45 m²), the wall's own outer
    side at y = 3.2 facing away (1 x 1 = 1 m²) and a neighbour's wall at y = 3.6 facing away (1 m²). Total
    41.45 m². Behind the front's plane (n = -y, d = -2.4) by more than 0.1 m: the wall (0.6 behind) and
    both back faces (0.8 and 1.2 behind); the wall's own back (within 0.3 m behind its plane, facing
    away) is left out only for a plane it is within 0.3 m of: for the front's plane it is 0.8 m back, so
    counted. Front: (15 + 1 + 1) / 41.45. Outer wall (d = -3): the own back at 0.2 is left out, the
    neighbour's at 0.6 counts: 1 / 41.45."""
    mesh = TriMesh(*concat_meshes([_floor(-1, 5, -1, 3), _quad(-1, 5, 3.0, 0, 2.5), _quad(0, 0.6, 2.4, 0.1, 0.85),
                                   _quad(0, 1, 3.2, 0, 1, towards_room=False), _quad(2, 3, 3.6, 0, 1, towards_room=False)]))
    n = np.array([0.0, -1.0, 0.0])
    total = 24 + 15 + 0.45 + 1 + 1
    assert abs(share_behind(mesh, n, -2.4, 0.1, 0.3, 0.9) - 17 / total) < 1e-9
    assert abs(share_behind(mesh, n, -3.0, 0.1, 0.3, 0.9) - 1 / total) < 1e-9
    assert share_behind(mesh, n, -3.0, 0.1, 0.0, 0.9) == 2 / total  # wall_back 0: every back face counts


def test_a_piece_stands_in_the_room_an_outer_wall_does_not() -> None:
    """The room of ``test_share_behind_by_hand`` without the two back faces: the cabinet front's plane
    (y = 2.4) has the outer wall 0.6 m behind it, 15 of 39.45 m² (0.38 >= ``room_wall.behind_share``
    0.005): a piece may stand there; the outer wall's plane (y = 3) has nothing behind it: a stretch of it
    seen between furniture, plain and filled like a fridge's front, is no piece."""
    mesh = TriMesh(*concat_meshes([_floor(-1, 5, -1, 3), _quad(-1, 5, 3.0, 0, 2.5), _quad(0, 0.6, 2.4, 0.1, 0.85)]))
    n, u = np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0])

    def plane(y: float) -> Plane:
        return Plane(n, u, -y, np.zeros(0, np.int64), (0.0, 1.0), (0.0, 2.0), 2.0)

    rw = RoomWallConfig()
    assert stands_in_room(mesh, plane(2.4), rw)
    assert not stands_in_room(mesh, plane(3.0), rw)
    assert stands_in_room(mesh, plane(3.0), RoomWallConfig(behind_share=0.0))


def test_a_plinth_cut_in_pieces_is_no_tiled_wall() -> None:
    """A 1 x 1 m plane at 1 cm per px, fully covered: two doors (50 x 90 px) over a 0.1 m plinth strip the
    door seams cut into four pieces, three of them tile-sized (0.2, 0.15 and 0.15 x 0.1 m; ``min_tiles`` 3).
    The strip runs along the coverage's bottom edge and is at most ``cells.edge_strip`` (0.2 m) tall, so the
    plane is no tiling; with ``tile_edge_strips`` it is (the rule before). Three 0.2 x 0.2 m cells in the
    middle of the plane make a tiling either way, and so does a row of three as small 0.3 m above the edge.
    The coverage's edge counts, not the grid's: a plane whose surface starts 30 px down has its top there."""
    cov = np.ones((100, 100), bool)
    plinth = [Cell(0, 90, 20, 100), Cell(20, 90, 35, 100), Cell(35, 90, 50, 100), Cell(50, 90, 100, 100)]
    cells = [Cell(0, 0, 50, 90), Cell(50, 0, 100, 90)] + plinth
    q = HeuristicConfig().cells
    assert not is_tiled(cells, cov, 0.01, q)
    assert is_tiled(cells, cov, 0.01, HeuristicConfig(cells={"tile_edge_strips": True}).cells)
    tiles = [Cell(0, 0, 100, 40), Cell(0, 40, 20, 60), Cell(20, 40, 40, 60), Cell(40, 40, 60, 60),
             Cell(60, 40, 100, 60), Cell(0, 60, 100, 100)]
    assert is_tiled(tiles, cov, 0.01, q)
    raised = [Cell(0, 0, 100, 60), Cell(0, 60, 20, 70), Cell(20, 60, 40, 70), Cell(40, 60, 60, 70),
              Cell(60, 60, 100, 70), Cell(0, 70, 100, 100)]
    assert is_tiled(raised, cov, 0.01, q)
    low = np.zeros((100, 100), bool)
    low[30:] = True
    top = [Cell(0, 30, 20, 40), Cell(20, 30, 40, 40), Cell(40, 30, 60, 40), Cell(60, 30, 100, 40), Cell(0, 40, 100, 100)]
    assert not is_tiled(top, low, 0.01, q)
    assert is_tiled(top, low, 0.01, HeuristicConfig(cells={"tile_edge_strips": True}).cells)


def test_seams_cutting_off_edge_strips_do_not_cut_a_wall_out() -> None:
    """A pale wall 1.2 m wide and 2 m tall at 4 mm per px (500 x 300 px) with a dark line 0.12 m below its
    top (a cornice, row 30) and one 0.1 m above its bottom (a skirting board, row 475). Both lines are
    straight seams along the whole plane, so the wall splits into a cornice strip, the wall and the skirting.
    As before (``cells.strip_seams`` on) the wall between them counts two seam cuts: a push-to-open front
    for ``cells.handleless_min_seams`` 2. A cut that takes off a strip at most ``cells.edge_strip`` tall along
    the cell's edge is no seam of the larger side: the wall counts none. A door between two vertical seams
    keeps its two seam cuts."""
    rng = np.random.default_rng(5)
    img = np.full((500, 300, 3), 0.8, np.float32) + rng.normal(0, 0.004, (500, 300, 3)).astype(np.float32)
    img[29:31] = 0.5
    img[474:476] = 0.5
    o = flat_ortho(img)
    cov = np.ones(img.shape[:2], bool)

    def wall(cfg: HeuristicConfig) -> Cell:
        cells = split_cells(o, cov, [], cfg)
        assert len(cells) == 3, [(c.r0, c.r1, c.c0, c.c1) for c in cells]
        return max(cells, key=lambda c: c.r1 - c.r0)

    assert wall(HeuristicConfig(cells={"strip_seams": True})).seam_cuts == 2
    assert wall(HeuristicConfig()).seam_cuts == 0
    door = img.copy()
    door[:, 49:51] = 0.5
    door[:, 249:251] = 0.5
    cells = split_cells(flat_ortho(door), cov, [], HeuristicConfig())
    leaf = max(cells, key=lambda c: (c.r1 - c.r0) * (c.c1 - c.c0))
    assert 49 <= leaf.c0 <= 51 and 249 <= leaf.c1 <= 251 and leaf.seam_cuts == 2
