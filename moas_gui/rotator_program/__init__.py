"""The MOAS Rotator program: TCP 13020 in front of serial rotator controllers."""
