"""Theory: the steady-swing tuning and the reduced (Kuramoto–Sakaguchi) description."""
