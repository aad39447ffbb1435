# Type stubs of the native module ridi._ridi (re-exported as `ridi`). The docstrings are the
# native ones: help(ridi.track) shows them in full.
import os
from typing import Any, Callable, Dict, List, Literal, Optional, Sequence as Seq, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

StrPath = Union[str, "os.PathLike[str]"]
Array = npt.NDArray[np.float64]
ArrayIn = npt.ArrayLike
"""An input array: float64 is read in place (copied when unaligned, as a record array's field),
other real dtypes and array-likes converted."""
Format = Literal["ridi-csv", "ridi-plain", "ridi-raw", "tyrex", "ilc", "ronin"]
Inputs = Union[StrPath, Seq[StrPath], Seq["Sequence"]]

METHODS: Tuple[str, ...]
"""Method keys of ``evaluate``: ridi, raw, pdr, ridi_mag, ridi_ori, velocity, still."""
RATE_HZ: float
"""The IMU rate every model assumes (200 Hz)."""

class Sequence:
    """One recording on one timeline, as numpy arrays (each property a new float64 array).

    Built from arrays, it is validated as any reader's input (equal lengths, finite values,
    increasing time in seconds, plausible units, gravity along the orientation's up axis); an
    error names the array and the frame. Orientations are world-from-device quaternions
    ``[w, x, y, z]``; the device frame is Android's. ``gravity`` defaults to the orientation's
    up axis; without both, they are estimated from gyro and accelerometer.
    """

    def __init__(
        self,
        time: ArrayIn,
        gyro: ArrayIn,
        acce: ArrayIn,
        gravity: Optional[ArrayIn] = None,
        orientation: Optional[ArrayIn] = None,
        *,
        linacce: Optional[ArrayIn] = None,
        name: str = "sequence",
        placement: Optional[str] = None,
        magnet: Optional[ArrayIn] = None,
        ground_truth_position: Optional[ArrayIn] = None,
        ground_truth_orientation: Optional[ArrayIn] = None,
        steps: Optional[ArrayIn] = None,
        orientation_source: Optional[
            Literal[
                "game-rotation-vector",
                "rotation-vector",
                "core-motion-attitude",
                "estimated",
                "ground-truth",
                "gyro-integration",
                "ekf",
            ]
        ] = None,
        device: Optional[str] = None,
        device_imu_rate_hz: Optional[float] = None,
    ) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def placement(self) -> Optional[str]: ...
    @property
    def format(self) -> Optional[Format]: ...
    @property
    def time(self) -> Array:
        """Timestamps, seconds, shape (N,)."""
    @property
    def gyro(self) -> Array:
        """Gyroscope, rad/s, device frame, shape (N, 3)."""
    @property
    def acce(self) -> Array:
        """Accelerometer with gravity, m/s², device frame, shape (N, 3)."""
    @property
    def linacce(self) -> Array:
        """Linear acceleration, m/s², device frame, shape (N, 3)."""
    @property
    def gravity(self) -> Array:
        """Gravity (pointing up), m/s², device frame, shape (N, 3)."""
    @property
    def magnet(self) -> Optional[Array]: ...
    @property
    def orientation(self) -> Array:
        """World-from-device quaternions ``[w, x, y, z]``, shape (N, 4)."""
    @property
    def orientation_source(self) -> Optional[str]: ...
    @property
    def ground_truth_position(self) -> Optional[Array]: ...
    @property
    def ground_truth_orientation(self) -> Optional[Array]: ...
    @property
    def steps(self) -> Optional[Array]: ...
    @property
    def device(self) -> Optional[str]: ...
    @property
    def device_imu_rate_hz(self) -> Optional[float]: ...
    @property
    def duration(self) -> float: ...
    @property
    def rate_hz(self) -> float: ...
    @property
    def median_rate_hz(self) -> float: ...
    def with_placement(self, placement: Optional[str]) -> "Sequence": ...
    def split_at_gaps(self, max_gap_s: float, min_duration_s: float = 0.0) -> List["Sequence"]: ...
    def resampled(self, rate_hz: float, max_gap_s: Optional[float] = None) -> "Sequence": ...
    def __len__(self) -> int: ...

class Model:
    """A trained model (placement classifier and velocity regressors). Pickles."""

    @property
    def placement_names(self) -> List[str]: ...
    @property
    def window(self) -> int: ...
    @property
    def orientation(self) -> Literal["recorded", "estimated"]: ...
    @property
    def up_axis(self) -> Literal["plus-or-minus-y", "plus-y"]: ...
    def save(self, path: StrPath) -> None: ...
    def describe(self) -> Dict[str, Any]:
        """What ``ridi inspect --json`` says of the model."""
    def to_bytes(self) -> bytes: ...
    @staticmethod
    def from_bytes(data: bytes) -> "Model": ...

class Regressions:
    """Regressed velocities ``[S-x, S-z]`` (m/s) at their frames, with their placements."""

    @property
    def frame(self) -> npt.NDArray[np.int64]: ...
    @property
    def velocity(self) -> Array: ...
    @property
    def placement(self) -> List[str]: ...
    def __len__(self) -> int: ...

class Track:
    """One pose per frame: world frame of the device orientation, metres from the start."""

    @property
    def time(self) -> Array: ...
    @property
    def position(self) -> Array: ...
    @property
    def velocity(self) -> Array: ...
    @property
    def bias(self) -> Array: ...
    @property
    def regressions(self) -> Regressions: ...
    @property
    def placement_names(self) -> List[str]: ...
    def write_csv(self, path: StrPath) -> None: ...
    def __len__(self) -> int: ...

class Update:
    """One frame's pose as a stream knows it."""

    @property
    def frame(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def position(self) -> Tuple[float, float, float]: ...
    @property
    def velocity(self) -> Tuple[float, float, float]: ...
    @property
    def bias(self) -> Tuple[float, float, float]: ...
    @property
    def restarted(self) -> bool: ...

class LiveTracker:
    """Tracks a stream sample by sample; a whole recording gives ``track(..., online=True)``."""

    def __init__(
        self,
        model: Model,
        *,
        regress_every: int = 50,
        lambda_: float = 0.1,
        estimate_initial_velocity: bool = False,
        placement_window: float = 10.0,
        heading: Literal["corrected", "gyro"] = "corrected",
    ) -> None: ...
    def push(
        self,
        time: float,
        gyro: Seq[float],
        acce: Seq[float],
        *,
        orientation: Optional[Seq[float]] = None,
        gravity: Optional[Seq[float]] = None,
        linacce: Optional[Seq[float]] = None,
    ) -> List[Update]: ...
    def finish(self) -> List[Update]: ...
    @property
    def regressions(self) -> Regressions: ...

def read(
    path: StrPath, format: Optional[Format] = None, *, split_at_gaps: Optional[float] = None
) -> Sequence:
    """The one recording at ``path``, in any format ridi-rs reads."""

def read_any(
    path: StrPath, format: Optional[Format] = None, *, split_at_gaps: Optional[float] = None
) -> List[Sequence]:
    """Every sequence at ``path`` (a Tyrex run split at a motion-capture loss, or a recording
    cut by ``split_at_gaps``, gives several)."""

def read_list(
    lists: Union[StrPath, Seq[StrPath]],
    *,
    placement_map: Optional[StrPath] = None,
    purpose: Optional[Literal["training", "evaluation"]] = None,
) -> List[Sequence]:
    """The sequences of list files (``path,placement`` per line)."""

def load(path: StrPath) -> Model:
    """A model file written by ``ridi train`` or ``Model.save``."""

def bundled_model() -> Model:
    """The model bundled with ridi-rs, trained on every shared Tyrex run."""

def train(
    data: Inputs,
    *,
    grid: Literal["paper", "small", "none"] = "paper",
    placement_map: Optional[StrPath] = None,
    orientation: Literal["recorded", "estimated"] = "estimated",
    storage: Literal["projected", "half"] = "projected",
    solver: Literal["exact", "nystrom"] = "exact",
    landmarks: Optional[int] = None,
    seed: int = 0,
    turned_copies: int = 1,
    step: Optional[int] = None,
    window: Optional[int] = None,
    speed: bool = True,
    up_axis: Literal["plus-or-minus-y", "plus-y"] = "plus-or-minus-y",
    standardize: bool = True,
    classifier_c: float = 10.0,
    jobs: Optional[int] = None,
    progress: Optional[Callable[[str, int, int], Optional[bool]]] = None,
) -> Model:
    """Trains a model as ``ridi train`` does, with its options and defaults."""

def regress(
    sequence: Sequence,
    model: Model,
    *,
    regress_every: int = 50,
    placement_window: float = 10.0,
) -> Regressions:
    """The velocities ``track`` corrects with."""

def track(
    sequence: Sequence,
    model: Model,
    online: bool = False,
    *,
    regress_every: int = 50,
    lambda_: float = 0.1,
    estimate_initial_velocity: bool = False,
    placement_window: float = 10.0,
    heading: Literal["corrected", "gyro"] = "corrected",
) -> Track:
    """Tracks a sequence as ``ridi track`` (``--online``) does."""

def evaluate(
    data: Inputs,
    model: Model,
    *,
    methods: Union[str, Seq[str], None] = None,
    placement_map: Optional[StrPath] = None,
    regress_every: int = 50,
    lambda_: float = 0.1,
    estimate_initial_velocity: bool = False,
    placement_window: float = 10.0,
    align: Union[float, Literal["all"], None] = None,
    heading: Literal["corrected", "gyro"] = "corrected",
    jobs: Optional[int] = None,
) -> Dict[str, Any]:
    """RIDI and its baselines against ground truth: the dict of ``report.json``."""

def compare(
    first: Union[Dict[str, Any], StrPath],
    second: Union[Dict[str, Any], StrPath],
) -> Dict[str, Any]:
    """Two evaluations of the same sequences, as ``ridi compare``: what differs and each
    figure's paired difference."""
