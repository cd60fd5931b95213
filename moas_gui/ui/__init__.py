"""moas_gui.ui."""
