"""moas_gui.hw."""
