"""Defaults of the audio analysis that the command line shows, in a module that imports
nothing heavy, so that building the ``metrosync`` parser stays quick."""

#: Band-pass edges of the tick detector, Hz, when none is given; at a sample rate too
#: low for its top, the top is lowered to `DEFAULT_TOP` × the sample rate.
DEFAULT_BAND = (1000.0, 10000.0)
DEFAULT_TOP = 0.45
#: Threshold above the detection curve's median, in its robust spreads.
DEFAULT_SENSITIVITY = 4.5
#: Largest phase gap inside one cluster of ticks, fraction of a beat.
CLUSTER_GAP = 1 / 16
