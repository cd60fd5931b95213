"""moas_gui.hw.rotators."""
