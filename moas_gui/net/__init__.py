"""moas_gui.net."""
