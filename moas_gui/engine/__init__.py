"""moas_gui.engine."""
