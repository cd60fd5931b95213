"""Rotator controllers on serial ports: one sans-IO codec and one emulator model per model."""
