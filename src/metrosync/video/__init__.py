"""Video: metronomes filmed by a phone (`camera`) and followed in a video (the tracker)."""
