"""The paper's studies by name, and what a reproduction costs: light to import.

The command line builds every subcommand's parser at each start, and `reproduce`'s help
and choices need only these; `catalogue` holds the studies themselves (a test keeps the
two lists one).
"""

#: The names of `catalogue.STUDIES`, in report order.
STUDY_NAMES = (
    "fig8_top", "fig8_bottom", "fig10", "fig11", "z", "estimation", "sigma_map", "claims_map",
)  # fmt: skip

#: What `metrosync reproduce` took, measured (`benchmarks/reproduce.py [--full]`).
MEASURED_COST = {
    "quick": "51 s measured on 2 cores (73 s of CPU) with the kernels compiled, the σ map "
    "and the claims map included; a first run compiles them too, once (about 32 s of CPU)",
    "full": "9 min 41 s measured on 2 cores (17 min 26 s of CPU), "
    "Fig. 10, the claims map and the σ map most of it",
}
