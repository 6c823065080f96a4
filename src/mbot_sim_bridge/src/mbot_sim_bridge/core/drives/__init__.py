"""The drive plugins: differential, holonomic (planar move), skid-steer and tricycle."""
