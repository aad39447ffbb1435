"""RIDI (Robust IMU Double Integration) from Python, at Rust speed.

ridi-rs turns a phone's IMU stream into a 2D walking trajectory: a support-vector cascade
regresses the walking velocity from one second of gravity-stabilized IMU data, an
accelerometer bias is corrected so that the integrated velocity follows it, and the corrected
accelerations are integrated twice. Each function calls the library function the matching
``ridi`` command calls, with the command's defaults, so that Python and the command line give
the same numbers.

>>> import ridi
>>> model = ridi.train("datasets/sample/list_train.txt", grid="none",
...                    placement_map="tyrex4")                       # doctest: +SKIP
>>> seq = ridi.read("datasets/sample/Thibaud_Nexus5_NoDist_Texting")  # doctest: +SKIP
>>> track = ridi.track(seq, model)                                  # doctest: +SKIP
>>> track.position.shape                                            # doctest: +SKIP
(4800, 3)
>>> report = ridi.evaluate("datasets/sample/list_test.txt", model,
...                        placement_map="tyrex4")                   # doctest: +SKIP
>>> report["summary"]["ridi"]["rte_5s_m"]                           # doctest: +SKIP

Files that cannot be read or written raise ``OSError``; wrong data, lists and options raise
``ValueError`` naming the file, line and field, or the sequence, array and frame, as the
command line does; an array of what is not a real number raises ``TypeError``.
"""

from ._ridi import (
    __version__,
    METHODS,
    RATE_HZ,
    LiveTracker,
    Model,
    Regressions,
    Sequence,
    Track,
    Update,
    bundled_model,
    compare,
    evaluate,
    load,
    read,
    read_any,
    read_list,
    regress,
    track,
    train,
)

__all__ = [
    "__version__",
    "METHODS",
    "RATE_HZ",
    "LiveTracker",
    "Model",
    "Regressions",
    "Sequence",
    "Track",
    "Update",
    "bundled_model",
    "compare",
    "evaluate",
    "load",
    "read",
    "read_any",
    "read_list",
    "regress",
    "track",
    "train",
]
