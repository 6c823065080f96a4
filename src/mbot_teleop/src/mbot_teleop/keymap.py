"""The course's key bindings, as data.

A move key picks a direction ``(x, th)``: the target linear speed is ``speed * x``
and the target angular speed ``turn * th``. A speed key multiplies
``(speed, turn)`` by its factors. The backward arcs steer like a car in reverse:
``m`` backs to the left (clockwise), ``.`` to the right.
"""

HELP = """
Control mbot!
---------------------------
Moving around:
   u    i    o
   j    k    l
   m    ,    .

q/z : increase/decrease max speeds by 10%
w/x : increase/decrease only linear speed by 10%
e/c : increase/decrease only angular speed by 10%
space key, k : force stop
anything else : stop smoothly

CTRL-C to quit
"""

MOVE_BINDINGS = {
    'i': (1, 0),
    'o': (1, -1),
    'j': (0, 1),
    'l': (0, -1),
    'u': (1, 1),
    ',': (-1, 0),
    '.': (-1, 1),
    'm': (-1, -1),
}

SPEED_BINDINGS = {
    'q': (1.1, 1.1),
    'z': (0.9, 0.9),
    'w': (1.1, 1.0),
    'x': (0.9, 1.0),
    'e': (1.0, 1.1),
    'c': (1.0, 0.9),
}

STOP_KEYS = frozenset({' ', 'k'})

# In raw mode CTRL-C reaches the program as this byte instead of SIGINT.
QUIT_KEY = '\x03'
