"""moas_gui.cli."""
