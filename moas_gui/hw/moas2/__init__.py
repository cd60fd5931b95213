"""moas_gui.hw.moas2."""
