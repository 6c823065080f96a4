"""Arranging with the mouse in the simulator window: PyBullet's own picking (left button on a body, drag).

A dynamic model dragged there stays where it is let go (then obeys gravity, as in Gazebo), the engine reports
its new pose (what get_model_state and /gazebo/model_states read) and a saved world holds it. A static model
has mass 0, which PyBullet cannot pick: it stays put (./mbot move places static models).
The simulation runs in this process (a Simulation in PyBullet's GUI mode) so the test can aim the mouse with the
window's camera; xdotool presses and moves the mouse on a private Xvfb display.
"""
import contextlib
import math
import os
import subprocess
import threading
import time

import numpy as np
import pybullet
import pytest
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.core.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.core.world_writer import take_snapshot, world_sdf, write_world_file

from xvfb import Xvfb

WORLDS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "worlds")
DRAG_TO = (1.5, 1.0)  # where the mouse lets the box go, in world x, y
WALL_SECONDS = 8.0  # the simulation steps at least this long while the mouse works
# With the button still down at the end of a drag, the box gets this many steps to catch up with the mouse: counted
# in steps, not wall time, because a loaded machine steps the simulation far fewer times a second.
HOLD_STEPS = 2000


def insert(simulation, tmp_path, database_name, name, x, y):
    xml = f"<sdf version='1.6'><world name='w'><include><uri>model://{database_name}</uri></include></world></sdf>"
    path = tmp_path / (f"{name}.world")
    path.write_text(spawn_world_xml(xml, name, pose_from_xyz_rpy((x, y, 0.0), (0.0, 0.0, 0.0))))
    simulation.add_world(parse_world(str(path)))


class WindowWithoutCamera(Exception):
    """PyBullet's window answered getDebugVisualizerCamera with zeros throughout: on a loaded machine a window
    at times never reports its camera (cause not found; a new window does)."""


def window_pixel(simulation, point):
    """Where a world point appears in the window, from its camera's view and projection matrices (read again until
    the window reports its camera: PyBullet answers zeros until then; the simulation keeps stepping meanwhile)."""
    client = simulation.engine.client
    deadline = time.monotonic() + 20.0
    while True:
        camera = client.getDebugVisualizerCamera()
        width, height = camera[0], camera[1]
        view, projection = np.array(camera[2]).reshape(4, 4).T, np.array(camera[3]).reshape(4, 4).T
        clip = projection @ view @ np.array([point[0], point[1], point[2], 1.0])
        if np.isfinite(clip).all() and abs(clip[3]) > 1e-9:
            break
        if time.monotonic() > deadline:
            raise WindowWithoutCamera(f"the window's camera was not set within 20 s: {camera[:4]}")
        simulation.step(1)
        time.sleep(0.05)
    x, y = clip[:2] / clip[3]
    return int(round((x + 1.0) / 2.0 * width)), int(round((1.0 - y) / 2.0 * height))


def xdotool(display, *arguments):
    subprocess.run(["xdotool", *arguments], env=dict(os.environ, DISPLAY=display), check=True, timeout=10)


def drag(display, start, end, steps):
    """Press on ``start``, move to ``end``, and let go once the simulation has stepped HOLD_STEPS more
    (``steps()`` counts them) or a minute has passed."""
    xdotool(display, "mousemove", *map(str, start))
    time.sleep(0.3)
    xdotool(display, "mousedown", "1")
    time.sleep(0.3)
    for step in range(1, 31):
        xdotool(display, "mousemove", *(str(a + (b - a) * step // 30) for a, b in zip(start, end)))
        time.sleep(0.05)
    held_from, deadline = steps(), time.monotonic() + 60.0
    while steps() - held_from < HOLD_STEPS and time.monotonic() < deadline:
        time.sleep(0.05)
    xdotool(display, "mouseup", "1")


@contextlib.contextmanager
def window_simulation(tmp_path):
    with Xvfb(tmp_path / "xvfb.log") as server:
        previous = os.environ.get("DISPLAY")
        os.environ["DISPLAY"] = server.display
        try:
            simulation = Simulation(parse_world(os.path.join(WORLDS, "empty.world")), {},
                                    connection_mode=pybullet.GUI)
        finally:
            os.environ.pop("DISPLAY") if previous is None else os.environ.update(DISPLAY=previous)
        try:
            # Straight down on the origin, so the window's axes are the world's.
            simulation.engine.client.resetDebugVisualizerCamera(6.0, 0.0, -89.0, (0.0, 0.0, 0.0))
            yield simulation, server
        finally:
            simulation.close()


def test_a_dragged_box_stays_where_it_is_left_and_is_saved_there(tmp_path):
    for attempt in range(2):
        folder = tmp_path / f"window_{attempt}"
        folder.mkdir()
        with window_simulation(folder) as (simulation, server):
            try:
                drag_and_check(simulation, server, folder)
                return
            except WindowWithoutCamera as error:
                print(f"{error}; opening a new window")
    pytest.fail("two windows in a row never reported their camera")


def drag_and_check(simulation, server, tmp_path):
    insert(simulation, tmp_path, "unit_box", "unit_box", 0.0, 0.0)
    insert(simulation, tmp_path, "cafe_table", "cafe_table", -1.5, -1.0)
    simulation.step(300)
    box_start = simulation.engine.model_pose("unit_box").position
    table_start = simulation.engine.model_pose("cafe_table")
    drags = [(window_pixel(simulation, (-1.5, -1.0, 0.755)), window_pixel(simulation, (-1.5, 1.0, 0.755))),  # the table
             (window_pixel(simulation, (0.0, 0.0, 1.0)), window_pixel(simulation, (*DRAG_TO, 1.0)))]  # the box's top

    def mouse_work():
        for start, end in drags:
            drag(server.display, start, end, lambda: simulation.engine.steps)
    mouse = threading.Thread(target=mouse_work)
    mouse.start()
    started = time.monotonic()
    while time.monotonic() - started < WALL_SECONDS or mouse.is_alive():
        simulation.step(5)  # PyBullet applies the picking constraint as the simulation steps
        time.sleep(0.002)
    mouse.join()
    # Let go, it comes to rest: wherever that is, it is far from the start, towards where the mouse went.
    for _ in range(100):
        simulation.step(100)
        linear, angular = simulation.engine.model_velocity("unit_box")
        if np.linalg.norm(linear) < 1e-3 and np.linalg.norm(angular) < 1e-3:
            break
    box = simulation.engine.model_pose("unit_box")
    moved = math.dist(box.position[:2], box_start[:2])
    assert moved > 0.5, f"the box moved {moved:.3f} m"
    assert np.dot(np.subtract(box.position[:2], box_start[:2]), DRAG_TO) > 0
    # The static table cannot be picked: the drag on it left it where it was.
    assert simulation.engine.model_pose("cafe_table") == table_start

    snapshot = take_snapshot(simulation, with_robots=False)
    path = tmp_path / "dragged.world"
    write_world_file(str(path), world_sdf(parse_world(os.path.join(WORLDS, "empty.world")), snapshot.models,
                                          snapshot.poses))
    (saved,) = [model for model in parse_world(str(path)).models if model.name == "unit_box"]
    assert math.dist(saved.pose.position, box.position) < 1e-3
