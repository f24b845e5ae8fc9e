"""Status of a run: the bits stored in every dataset's ``status`` variable.

A run's status is a bit mask (CF flag masks: the ``status`` variable's ``flag_masks``
and ``flag_meanings`` attributes repeat this table in every file). Zero means the run
finished normally and its r is meaningful.

=====  ==========  ===============================================================
bit    name        meaning
=====  ==========  ===============================================================
1      overturned  some pendulum's |θ| passed ``overturn_angle`` (default π/2): the
                   small-swing model no longer describes it; its r is not meaningful
2      diverged    a non-finite value appeared; the run was stopped at that step
4      failed      sweeps only: the point's simulation raised, so the run has no
                   result at all (the sweep's log says why)
8      stopped     some metronome's escapement gave no impulse in the run's last two
                   periods of that metronome: its swing no longer reaches the
                   escapement's angle, the drive is off and the pendulum decays
                   ("metronome death", Goldsztein et al., Chaos 32, 043119 (2022));
                   the run's r measures decaying pendulums, not synchrony
=====  ==========  ===============================================================

``STATUS_ABSENT`` (−1) marks, in a merged sweep, a run that does not exist because its
point has fewer runs than the largest point; it is not a flag.
"""

STATUS_OK = 0
STATUS_OVERTURNED = 1
STATUS_DIVERGED = 2
STATUS_FAILED = 4
STATUS_STOPPED = 8
STATUS_ABSENT = -1

#: The bits a simulation can set, with their names (the file's ``flag_meanings``).
STATUS_MEANINGS = {
    STATUS_OVERTURNED: "overturned",
    STATUS_DIVERGED: "diverged",
    STATUS_STOPPED: "stopped",
}
#: The bits a sweep's merged dataset can hold, in bit order.
SWEEP_FLAG_MEANINGS = dict(sorted({**STATUS_MEANINGS, STATUS_FAILED: "failed"}.items()))


def describe(status: int) -> str:
    """Words for a status value: ``describe(3) == 'overturned, diverged'``."""
    if status == STATUS_ABSENT:
        return "absent"
    names = [name for bit, name in SWEEP_FLAG_MEANINGS.items() if status & bit]
    return ", ".join(names) if names else "ok"
