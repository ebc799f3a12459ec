import math

import numpy as np
import pytest

from tanktool.nav.navgrid import grid_from_mask
from tanktool.nav.steering import (
    children,
    choose_next,
    decide,
    heading_angle,
    heading_from_angle,
    heading_of_move,
    nodes_ahead,
    run_ahead,
    turn_left,
    turn_right,
)


def mask(text: str) -> np.ndarray:
    """Rows top to bottom are i = 0, 1, ...; '.' valid, '#' invalid; other letters valid."""
    return np.array([[c != "#" for c in line.strip()] for line in text.strip().splitlines()])


def test_headings_follow_the_world_convention():
    assert heading_from_angle(0.0) == "+x" and heading_from_angle(math.pi / 2) == "+z"
    assert heading_from_angle(-math.pi / 2 + 0.1) == "-z" and heading_from_angle(3.2) == "-x"
    assert heading_angle("+z") == pytest.approx(math.pi / 2)
    # right of facing f is (-f_z, f_x): right of +x is +z
    assert [turn_right(h) for h in ("+x", "+z", "-x", "-z")] == ["+z", "-x", "-z", "+x"]
    assert [turn_left(turn_right(h)) for h in ("+x", "+z", "-x", "-z")] == ["+x", "+z", "-x", "-z"]
    with pytest.raises(ValueError, match="heading must be one of"):
        turn_left("north")
    assert turn_left(math.pi) == "+z"  # angles are snapped


def test_nodes_ahead_mapping_for_all_four_headings():
    g = grid_from_mask(mask("""
        #######
        #.....#
        #.....#
        #.....#
        #######
    """))
    # node (2, 2): row run j=1..5 (index 2 of 5), column run i=1..3 (index 2 of 3)
    assert (g.row_index[0, 2, 2], g.row_total[0, 2, 2], g.col_index[0, 2, 2], g.col_total[0, 2, 2]) == (2, 5, 2, 3)
    assert nodes_ahead(g, (2, 2), "+x") == 3  # row_total - row_index
    assert nodes_ahead(g, (2, 2), "-x") == 1  # row_index - 1
    assert nodes_ahead(g, (2, 2), "+z") == 1  # col_total - col_index
    assert nodes_ahead(g, (2, 2), "-z") == 1  # col_index - 1
    # the counts equal a walk to the wall
    for h, (di, dj) in {"+x": (0, 1), "-x": (0, -1), "+z": (1, 0), "-z": (-1, 0)}.items():
        for node in zip(*np.nonzero(g.valid[0])):
            n, (i, j) = 0, node
            while g.valid[0][i + di, j + dj]:
                i, j, n = i + di, j + dj, n + 1
            assert nodes_ahead(g, node, h) == n
    assert nodes_ahead(g, (0, 0), "+x") == 0


UNAMBIGUOUS = """
    ########
    ###.####
    ###.####
    #A...###
    ###.####
    ###.####
    ###.####
    ###.####
    ###.####
    ###.####
    ########
"""


def test_unambiguous_right_turn():
    # at A = (3, 1) facing +x the children are (2, 2)? no: A's step ahead is (3, 2);
    # start one node in so that the three children are (2, 3), (3, 3), (4, 3)
    g = grid_from_mask(mask(UNAMBIGUOUS))
    kids = {c.name: c for c in children(g, (3, 2), "+x")}
    assert kids["left"].node == (2, 3) and kids["left"].heading == "-z" and kids["left"].ahead == 1
    assert kids["ahead"].node == (3, 3) and kids["ahead"].heading == "+x" and kids["ahead"].ahead == 1
    assert kids["right"].node == (4, 3) and kids["right"].heading == "+z" and kids["right"].ahead == 5
    assert choose_next(g, (3, 2), "+x") == (4, 3)
    assert choose_next(g, (3, 2), 0.1) == (4, 3)  # a world angle snaps to +x
    # mirrored (rows reversed): the long corridor is now on the left
    m = grid_from_mask(mask(UNAMBIGUOUS)[::-1])
    assert choose_next(m, (7, 2), "+x") == (6, 3)


def test_ties_go_straight_then_right():
    assert decide({"left": 3, "ahead": 3, "right": 3}) == "ahead"
    assert decide({"left": 4, "ahead": 3, "right": 4}) == "right"
    assert decide({"left": 5, "right": 4}) == "left"
    assert decide({}) is None
    g = grid_from_mask(mask("""
        #######
        #.....#
        #.....#
        #.....#
        #######
    """))
    # facing +x from (2, 2): left (1,3) -z: 0, ahead (2,3) +x: 2, right (3,3) +z: 0
    assert choose_next(g, (2, 2), "+x") == (2, 3)
    # facing +z from (2, 3), children on the wall row are invalid -> turn in place
    assert choose_next(g, (3, 3), "+z") in {(3, 2), (3, 4)}
    # right of +z is -x: (3, 2) has 1 node further -x, (3, 4) has 1 node +x: tie -> right
    assert choose_next(g, (3, 3), "+z") == (3, 2)


def test_boxed_in_and_dead_ends():
    g = grid_from_mask(mask("""
        #####
        #.###
        #.###
        #####
    """))
    # facing +z at the bottom of a dead end: nothing ahead, nothing to the sides: go back
    assert choose_next(g, (2, 1), "+z") == (1, 1)
    lone = grid_from_mask(mask("""
        ###
        #.#
        ###
    """))
    assert choose_next(lone, (1, 1), "-x") is None


# drawn as in our pictures: z up, so the top line is the highest row i
PAPER_FIGURE = """
    ###############
    ######.########
    ######G########
    ####..........#
    ######.########
    ###############
"""


def test_grid_shaped_like_the_paper_figure():
    """The paper's example: the grey node heading down, three children in front, HIJO 1
    (ahead-right) leading along a long row, HIJO 2 (straight) a short column, HIJO 3
    (ahead-left) a short way to a wall.  Our pictures have z up, so "down" is -z and
    its right is +x."""
    g = grid_from_mask(mask(PAPER_FIGURE)[::-1])
    node, heading = (3, 6), "-z"
    kids = {c.name: c for c in children(g, node, heading)}
    hijo1, hijo2, hijo3 = kids["right"], kids["ahead"], kids["left"]
    assert (hijo1.node, hijo2.node, hijo3.node) == ((2, 7), (2, 6), (2, 5))
    table = {
        name: (int(g.row_index[0][c.node]), int(g.col_index[0][c.node]), int(g.row_total[0][c.node]), int(g.col_total[0][c.node]))
        for name, c in (("HIJO 1", hijo1), ("HIJO 2", hijo2), ("HIJO 3", hijo3))
    }
    # renglon, columna, total renglones, total columnas: a row of 10 as in the paper
    assert table == {"HIJO 1": (4, 1, 10, 1), "HIJO 2": (3, 2, 10, 4), "HIJO 3": (2, 1, 10, 1)}
    assert (hijo1.ahead, hijo2.ahead, hijo3.ahead) == (6, 1, 1)
    assert choose_next(g, node, heading) == hijo1.node
    assert heading_of_move(node, hijo1.node, heading) == "+x"  # the agent turns right


def test_paper_table_numbers_single_out_hijo_1():
    """The paper's table, read with each child's count taken in the direction it leads,
    on a figure drawn with z up (so "down" is -z and its right is +x).  The three rows
    cannot come from one grid (side-by-side children share a row run), but the rule
    applied to the printed numbers picks HIJO 1 as the paper says."""
    heading = "-z"
    table = {"right": (8, 1, 10, 2), "ahead": (9, 2, 10, 3), "left": (1, 2, 10, 4)}  # HIJO 1, 2, 3
    travel = {"right": turn_right(heading), "ahead": heading, "left": turn_left(heading)}
    scores = {k: run_ahead(*v, travel[k]) for k, v in table.items()}
    assert scores == {"right": 2, "ahead": 1, "left": 0}
    assert decide(scores) == "right"


def test_heading_of_move():
    assert heading_of_move((3, 3), (3, 4), "+x") == "+x"
    assert heading_of_move((3, 3), (4, 4), "+x") == "+z"   # ahead-right of +x
    assert heading_of_move((3, 3), (2, 4), "+x") == "-z"   # ahead-left of +x
    assert heading_of_move((3, 3), (3, 2), "+z") == "-x"


ROOT = __import__("pathlib").Path(__file__).resolve().parent.parent
BUNDLED = sorted(p.parent for p in ROOT.glob("arenas/*/arena.toml"))


@pytest.mark.parametrize("folder", BUNDLED, ids=[p.name for p in BUNDLED])
def test_agent_walk_on_bundled_arenas(folder):
    """An agent steering by the heuristic alone from each spawn point never leaves the
    valid nodes, and every move is one of the three children or a turn in place."""
    from tanktool.arena import load_arena
    from tanktool.nav.navgrid import build_navgrid

    arena = load_arena(folder)
    g = build_navgrid(arena.walls, 1.0, 2.0, spawns=arena.spawns)
    assert g.spawn_nodes
    for spawn, node in zip(arena.spawns, (n[1:] for n in g.spawn_nodes)):
        h = heading_from_angle(spawn[2])
        for _ in range(150):
            nxt = choose_next(g, node, h)
            assert nxt is not None and g.valid[0][nxt] and g.reachable[0][nxt]
            ahead = {c.node for c in children(g, node, h)}
            di, dj = nxt[0] - node[0], nxt[1] - node[1]
            assert nxt in ahead or (abs(di) + abs(dj) == 1 and not ahead)
            h = heading_of_move(node, nxt, h)
            node = nxt
