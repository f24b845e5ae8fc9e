"""Pantaleone's metronomes on a board (Am. J. Phys. 70, 992 (2002)), reproduced.

`averaged` is his averaged theory at his parameters, `observations` runs each of his
observations on the ``pantaleone2002`` board, and `report` writes PANTALEONE.md, its
figure and its data (``metrosync pantaleone``).
"""
