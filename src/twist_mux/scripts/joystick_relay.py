#!/usr/bin/env python3
from twist_mux.joystick_relay import main

main()
