"""Arranging with the mouse in the simulator window: PyBullet's own picking (left button on a body, drag).

A dynamic model dragged there hangs from the mouse on PyBullet's pick spring; let go, it falls, comes to rest and
stays there, the engine reports its new pose (what get_model_state and /gazebo/model_states read) and a saved world
holds it. A static model has mass 0, which PyBullet cannot pick: it stays put (./mbot move places static models).
The simulation runs in this process (a Simulation in PyBullet's GUI mode) so the test can aim the mouse with the
window's camera; xdotool presses and moves the mouse on a private Xvfb display.
"""
import gc
import math
import os
import subprocess
import time
from unittest import mock

import numpy as np
import pybullet
import pytest
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, yaw
from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.core.description.world_writer import take_snapshot, world_sdf, write_world_file

from ros_processes import wait_until
from xvfb import Xvfb

WORLDS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "worlds")
DRAG_TO = (1.5, 1.0)  # where the mouse lets the box go, in world x, y
# Every wait below is on a condition checked between simulation steps, with a wall-time limit only for failure:
# a loaded machine steps and draws far fewer times a second (in GUI mode every PyBullet call waits for the
# window's thread: under a load of 15 on 2 cores a second of sim time took 25 s).
WALL_TIMEOUT = 180.0
# The window's thread draws a frame between the simulation's calls, in software OpenGL: at PyBullet's 1024x768 with
# shadows a frame was most of the test's CPU. A 1 m box seen from 6 m is still 40 pixels wide at this size.
WINDOW_SIZE = (320, 240)
REST_SPEED = 1e-3  # m/s and rad/s: the box has come to rest
STAYS_SECONDS = 1.0  # sim time it must then stay put for
STAYS_TOLERANCE = 1e-4  # m and rad (measured: under 0.01 mm)
RELEASED_STEPS = 100  # steps between checks once the mouse has let go: rest is seen to within 0.1 s of sim time
# getMouseEvents' event types (PyBullet's quickstart guide; the module has no names for them).
MOUSE_MOVE_EVENT, MOUSE_BUTTON_EVENT = 1, 2


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


class Mouse:
    """The mouse on the window, each action awaited until the window reports it (getMouseEvents), with the
    simulation stepping meanwhile: PyBullet picks and drags bodies as the window handles the events."""

    def __init__(self, simulation, display):
        self.simulation, self.display = simulation, display
        self.client = simulation.engine.client

    def step_until(self, condition, what, steps=5):
        """Step ``steps`` at a time until ``condition()``. Each pause for the window's thread costs a frame drawn:
        with the mouse at rest, larger ``steps`` draw fewer of them."""
        deadline = time.monotonic() + WALL_TIMEOUT
        while not condition():
            assert time.monotonic() < deadline, f"timed out after {WALL_TIMEOUT:g} s waiting for {what}"
            self.simulation.step(steps)
            time.sleep(0.002)  # the window's thread gets the lock between steps

    def events_until(self, wanted, what):
        self.step_until(lambda: any(wanted(event) for event in self.client.getMouseEvents()), what)

    def move(self, pixel):
        xdotool(self.display, "mousemove", *map(str, pixel))
        self.events_until(lambda event: event[0] == MOUSE_MOVE_EVENT and event[1:3] == tuple(pixel),
                          f"the window to see the mouse at {pixel}")

    def button(self, action, state):
        xdotool(self.display, action, "1")
        self.events_until(lambda event: event[0] == MOUSE_BUTTON_EVENT and event[3] == 0 and event[4] & state,
                          f"the window to see {action}")

    def drag(self, start, end, held_until, what):
        """Press on ``start``, move to ``end`` in steps, and let go once ``held_until()`` holds."""
        self.move(start)
        self.button("mousedown", pybullet.KEY_WAS_TRIGGERED)
        for step in range(1, 11):
            self.move(tuple(a + (b - a) * step // 10 for a, b in zip(start, end)))
        self.step_until(held_until, what)
        self.button("mouseup", pybullet.KEY_WAS_RELEASED)


@pytest.fixture
def window_simulation(tmp_path):
    # PyBullet's window never reports its camera (zeros) while any other PyBullet client is connected in the
    # process; earlier tests in this pytest worker may have left simulations waiting for the garbage collector
    # (reference cycles between a simulation and its plugins), whose clients disconnect when collected.
    gc.collect()
    with Xvfb(tmp_path / "xvfb.log") as server:
        with mock.patch.dict(os.environ, server.environment({})):
            simulation = Simulation(parse_world(os.path.join(WORLDS, "empty.world")), {},
                                    connection_mode=pybullet.GUI)
        try:
            client = simulation.engine.client
            client.configureDebugVisualizer(pybullet.COV_ENABLE_SHADOWS, 0)
            xdotool(server.display, "search", "--sync", "--name", "^Bullet Physics", "windowsize", "--sync", "%@",
                    *map(str, WINDOW_SIZE))
            wait_until(lambda: client.getDebugVisualizerCamera()[:2] == WINDOW_SIZE, 20,
                       f"the window to take the size {WINDOW_SIZE}")
            # Straight down on the origin, so the window's axes are the world's.
            client.resetDebugVisualizerCamera(6.0, 0.0, -89.0, (0.0, 0.0, 0.0))
            yield simulation, server
        finally:
            simulation.close()


def at_rest(simulation, name):
    linear, angular = simulation.engine.model_velocity(name)
    return np.linalg.norm(linear) < REST_SPEED and np.linalg.norm(angular) < REST_SPEED


def test_a_dragged_box_stays_where_it_is_left_and_is_saved_there(window_simulation, tmp_path):
    simulation, server = window_simulation
    insert(simulation, tmp_path, "unit_box", "unit_box", 0.0, 0.0)
    insert(simulation, tmp_path, "cafe_table", "cafe_table", -1.5, -1.0)
    simulation.step(300)
    client = simulation.engine.client
    box_start = simulation.engine.model_pose("unit_box").position
    table_start = simulation.engine.model_pose("cafe_table")
    mouse = Mouse(simulation, server.display)

    # The static table cannot be picked: a drag on it, held 0.1 s, leaves it where it was.
    held_from = simulation.sim_time
    mouse.drag(window_pixel(client, (-1.5, -1.0, 0.755)), window_pixel(client, (-1.5, 1.0, 0.755)),
               lambda: simulation.sim_time > held_from + 0.1, "0.1 s of sim time")
    assert simulation.engine.model_pose("cafe_table") == table_start

    # The box, picked on its top, hangs from the mouse on PyBullet's pick spring and circles under it at 6 to 8 m/s
    # while the button is down (measured over 1.5 s), so wherever it is let go it is thrown: let go once it has
    # been carried a metre, it lands 2 to 27 m away (measured) and comes to rest, then stays there.
    def carried():
        return math.dist(simulation.engine.model_pose("unit_box").position[:2], box_start[:2]) > 1.0
    mouse.drag(window_pixel(client, (0.0, 0.0, 1.0)), window_pixel(client, (*DRAG_TO, 1.0)), carried,
               "the box to follow the mouse a metre")
    mouse.step_until(lambda: at_rest(simulation, "unit_box"), "the box to come to rest", RELEASED_STEPS)
    box = simulation.engine.model_pose("unit_box")
    rest_time = simulation.sim_time
    mouse.step_until(lambda: simulation.sim_time >= rest_time + STAYS_SECONDS, f"{STAYS_SECONDS} s of sim time",
                     RELEASED_STEPS)
    stayed = simulation.engine.model_pose("unit_box")
    moved = math.dist(box.position[:2], box_start[:2])
    print(f"figure: dragged box left at ({box.position[0]:.3f}, {box.position[1]:.3f}) m, {moved:.3f} m from its "
          f"start; it moved {math.dist(stayed.position, box.position) * 1000:.3f} mm in the {STAYS_SECONDS:g} s after")
    assert moved > 0.5 and np.dot(np.subtract(box.position[:2], box_start[:2]), DRAG_TO) > 0
    assert math.dist(stayed.position, box.position) < STAYS_TOLERANCE
    assert abs(math.remainder(yaw(stayed.orientation) - yaw(box.orientation), 2 * math.pi)) < STAYS_TOLERANCE

    snapshot = take_snapshot(simulation, with_robots=False)
    path = tmp_path / "dragged.world"
    write_world_file(str(path), world_sdf(parse_world(os.path.join(WORLDS, "empty.world")), snapshot.models,
                                          snapshot.poses))
    (saved,) = [model for model in parse_world(str(path)).models if model.name == "unit_box"]
    assert math.dist(saved.pose.position, stayed.position) < 1e-3
