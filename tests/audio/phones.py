"""Recordings of the audio tests made by two phones at once."""

from __future__ import annotations


def two_phone_files(tmp_path, bpms):
    """Two metronomes of one make at ``bpms``, each near its own phone: a.wav starts 0.73 s
    into the session, b.wav at 0 s. (paths, the true tick times at microphone 0 on
    a.wav's time line)."""
    import soundfile as sf

    from metrosync import synthetic
    from metrosync.synthetic import voices

    sound = voices(1, 4)[0]
    trains = [synthetic.steady_train(b, 40, phase=p, voice=sound, seed=i, jitter_s=0.5e-3)
              for i, (b, p) in enumerate(zip(bpms, (0.1, 0.6), strict=True))]  # fmt: skip
    near = [synthetic.Microphone((1.0, 0.25), (0.0, 0.001)),
            synthetic.Microphone((0.25, 1.0), (0.001, 0.0))]  # fmt: skip
    rec = synthetic.make_recording(trains, microphones=near,
                                   impairments=synthetic.Impairments.phone(), seed=4)  # fmt: skip
    late = round(0.73 * rec.sample_rate)
    a, b = tmp_path / "a.wav", tmp_path / "b.wav"
    sf.write(str(a), rec.samples[late:, 0], rec.sample_rate)
    sf.write(str(b), rec.samples[:, 1], rec.sample_rate)
    return [a, b], [t.times - 0.73 for t in rec.truth]
