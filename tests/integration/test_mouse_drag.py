"""Arranging with the mouse in the simulator window: PyBullet's own picking (left button on a body, drag).

A dynamic model dragged there stays where it is let go (then obeys gravity, as in Gazebo), the engine reports
its new pose (what get_model_state and /gazebo/model_states read) and a saved world holds it. A static model
has mass 0, which PyBullet cannot pick: it stays put (./mbot move places static models).
The simulation runs in this process (a Simulation in PyBullet's GUI mode) so the test can aim the mouse with the
window's camera; xdotool presses and moves the mouse on a private Xvfb display.
"""
import gc
import math
import os
import subprocess
import threading
import time

import numpy as np
import pybullet
import pytest
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.core.description.world_writer import take_snapshot, world_sdf, write_world_file

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


def window_pixel(client, point):
    """Where a world point appears in the window, from its camera's view and projection matrices (read again until
    the window has applied the camera: before that they are zero)."""
    deadline = time.monotonic() + 20.0
    while True:
        camera = client.getDebugVisualizerCamera()
        width, height = camera[0], camera[1]
        view, projection = np.array(camera[2]).reshape(4, 4).T, np.array(camera[3]).reshape(4, 4).T
        clip = projection @ view @ np.array([point[0], point[1], point[2], 1.0])
        if np.isfinite(clip).all() and abs(clip[3]) > 1e-9:
            break
        assert time.monotonic() < deadline, f"the window's camera was not set within 20 s: {camera[:4]}"
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


@pytest.fixture
def window_simulation(tmp_path):
    # PyBullet's window never reports its camera (zeros) while any other PyBullet client is connected in the
    # process; earlier tests in this pytest worker may have left simulations waiting for the garbage collector
    # (reference cycles between a simulation and its plugins), whose clients disconnect when collected.
    gc.collect()
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


def test_a_dragged_box_stays_where_it_is_left_and_is_saved_there(window_simulation, tmp_path):
    simulation, server = window_simulation
    insert(simulation, tmp_path, "unit_box", "unit_box", 0.0, 0.0)
    insert(simulation, tmp_path, "cafe_table", "cafe_table", -1.5, -1.0)
    simulation.step(300)
    client = simulation.engine.client
    box_start = simulation.engine.model_pose("unit_box").position
    table_start = simulation.engine.model_pose("cafe_table")
    drags = [(window_pixel(client, (-1.5, -1.0, 0.755)), window_pixel(client, (-1.5, 1.0, 0.755))),  # the table
             (window_pixel(client, (0.0, 0.0, 1.0)), window_pixel(client, (*DRAG_TO, 1.0)))]  # the box's top

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
