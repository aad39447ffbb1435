#!/usr/bin/env python3
"""Writes the committed corpus of hostile inputs that `tests/corpus.rs` runs `ridi` on.

Run once after changing it (`python3 crates/ridi-cli/tests/corpus/make.py`) and commit what it
writes; the output is deterministic (fixed seed, gzip without a time stamp). Standard library
only. What each file is and what `ridi` must do with it is in `expected.txt`, beside this
script; the large inputs (a gzip bomb, a long recording, Tyrex runs of 10 s) and the names a
checkout cannot hold (control characters) are made by the test itself, in a temporary folder.

Every file is small: the corpus stays under 300 KB. The reference recording `ok/` is a
synthetic walk that passes every check of the readers (docs/formats.md, "What the readers
refuse"): a phone lying flat, turning about the vertical at 0.5 rad/s while its holder walks a
circle at 1 m/s, bouncing at 2 Hz; 240 frames at 200 Hz, more than one 200-frame feature
window, so it can be tracked and evaluated. The recordings in `csv/` and `plain/` are copies
of it (most of its first 24 frames) with one thing wrong; the other folders hold raw recorder
folders, Indoor Location Competition path files, RoNIN folders, model files, list files and
awkward names, each described where it is written below.
"""

import gzip
import math
import os
import random
import shutil
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
# The folders this script owns (and empties first); expected.txt, make.py and .gitattributes
# (no line-end conversion: the files are inputs byte for byte) stay.
OUTPUTS = ["ok", "csv", "plain", "raw", "ilc", "ronin", "model", "lists", "names", "demo"]

COLUMNS = (
    ["", "time"]
    + [f"{c}_{a}" for c in ["gyro", "acce", "linacce", "grav", "magnet", "pos"] for a in "xyz"]
    + [f"{c}_{a}" for c in ["ori", "rv"] for a in "wxyz"]
)
T0_NS = 10_000_000_000
STEP_NS = 5_000_000
# Frames of the mutated copies.
SHORT = 24
YAW_RATE = 0.5  # rad/s
SPEED = 1.0  # m/s
G = 9.80665


def num(v):
    """A value as a short decimal that reads back close enough (6 significant digits)."""
    text = "%.6g" % v
    return "0" if text in ("-0", "0") else text


def frame(i):
    """The reference walk's frame `i` as the 28 cells of a `data.csv` row (index first)."""
    t = i * STEP_NS / 1e9
    yaw = YAW_RATE * t
    q = [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]  # w x y z: about the vertical
    bounce = 2 * math.pi * 2.0 * t
    lin = [0.4 * math.sin(bounce), 0.3 * math.cos(bounce), 1.2 * math.sin(bounce)]
    grav = [0.0, 0.0, G]
    acce = [a + g for a, g in zip(lin, grav)]
    radius = SPEED / YAW_RATE
    pos = [radius * math.sin(yaw), radius * (1 - math.cos(yaw)), 1.2]
    values = [0.0, 0.0, YAW_RATE] + acce + lin + grav + [0.0, 0.0, 0.0] + pos + q + q
    return [str(i), str(T0_NS + i * STEP_NS)] + [num(v) for v in values]


def csv_text(rows, header=COLUMNS):
    return "".join(",".join(r) + "\n" for r in [header] + rows)


def rows(n):
    return [frame(i) for i in range(n)]


def write(rel, data):
    path = os.path.join(HERE, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


def col(name):
    return COLUMNS.index(name)


def edited(n, edit):
    """The first `n` frames with `edit(i, row)` applied to each data row (0-based)."""
    out = []
    for i, r in enumerate(rows(n)):
        r = list(r)
        edit(i, r)
        out.append(r)
    return out


def set_cell(at, name, value):
    def edit(i, r):
        if i == at:
            r[col(name)] = value

    return edit


def scale(names, factor):
    def edit(i, r):
        for name in names:
            r[col(name)] = num(float(r[col(name)]) * factor)

    return edit


def processed_csvs(rng):
    full = rows(240)
    write("ok/processed/data.csv", csv_text(full))
    # Its placement label, where the RIDI layout keeps labels (`ridi convert` reads it).
    write("ok/list.txt", "# the reference walk, as a list of one\nprocessed/data.csv,Texting\n")
    short = rows(SHORT)
    # Mutated copies of the first SHORT frames; the line of a data row is its index + 2.
    write("csv/missing-column.csv", csv_text(
        [r[: col("gyro_y")] + r[col("gyro_y") + 1:] for r in short],
        COLUMNS[: col("gyro_y")] + COLUMNS[col("gyro_y") + 1:]))
    # An unknown column between two known ones: columns are chosen by name, so it reads.
    extra_at = col("acce_x")
    write("csv/extra-column.csv", csv_text(
        [r[:extra_at] + ["21.5"] + r[extra_at:] for r in short],
        COLUMNS[:extra_at] + ["temperature"] + COLUMNS[extra_at:]))
    write("csv/extra-cell.csv", csv_text(edited(SHORT, lambda i, r: r.append("7") if i == 9 else None)))
    write("csv/short-row.csv", csv_text(edited(SHORT, lambda i, r: r.pop() if i == 9 else None)))
    write("csv/nan-gyro.csv", csv_text(edited(SHORT, set_cell(5, "gyro_y", "NaN"))))
    write("csv/inf-acce.csv", csv_text(edited(SHORT, set_cell(15, "acce_z", "inf"))))
    write("csv/huge-acce.csv", csv_text(edited(SHORT, set_cell(12, "acce_x", "1e308"))))
    write("csv/not-a-number.csv", csv_text(edited(SHORT, set_cell(3, "linacce_z", "1.2.3"))))
    # A terminal escape sequence inside a cell: the error quotes it escaped.
    write("csv/escape-in-cell.csv", csv_text(edited(SHORT, set_cell(7, "grav_x", "\x1b[31mred"))))
    t = col("time")
    write("csv/time-backwards.csv", csv_text(edited(
        SHORT, lambda i, r: r.__setitem__(t, str(T0_NS + 9 * STEP_NS - 1)) if i == 11 else None)))
    write("csv/time-repeated.csv", csv_text(edited(
        SHORT, lambda i, r: r.__setitem__(t, str(T0_NS + 9 * STEP_NS)) if i == 10 else None)))
    # Times in seconds where nanoseconds belong.
    write("csv/time-in-seconds.csv", csv_text(edited(
        SHORT, lambda i, r: r.__setitem__(t, num(10 + i * 0.005)))))
    # Gaps: 0.5 s is read (and reported) but not tracked (over 0.1 s); 2 s is refused.
    def gap(seconds):
        return lambda i, r: r.__setitem__(t, str(int(r[t]) + int(seconds * 1e9))) if i >= 120 else None
    # Compressed: it is as long as the reference, to be tracked.
    write("csv/gap.csv.gz", gzip.compress(csv_text(edited(240, gap(0.5))).encode(), mtime=0))
    write("csv/big-gap.csv", csv_text(edited(SHORT, lambda i, r: r.__setitem__(
        t, str(int(r[t]) + 2_000_000_000)) if i >= 12 else None)))
    # Cut off while being written: the last value is cut short and has no line break.
    text = csv_text(short)
    write("csv/truncated.csv", text[: text.rindex(",") + 3])
    write("csv/empty.csv", "")
    write("csv/header-only.csv", csv_text([]))
    write("csv/no-header.csv", "".join(",".join(r) + "\n" for r in short))
    write("csv/garbage.csv", bytes(rng.randrange(256) for _ in range(1024)))
    # Valid UTF-8 up to a Latin-1 byte on line 4.
    latin = csv_text(short[:10]).encode()
    nth = [k for k, b in enumerate(latin) if b == 10][2] + 1
    write("csv/latin1.csv", latin[:nth] + b"0,caf\xe9" + latin[nth:])
    write("csv/crlf.csv", csv_text(short).replace("\n", "\r\n"))
    # Units: gyro in deg/s, accelerometer (and gravity) in g, positions in mm.
    write("csv/gyro-deg.csv", csv_text(edited(SHORT, scale(["gyro_x", "gyro_y", "gyro_z"], 180 / math.pi))))
    write("csv/acce-in-g.csv", csv_text(edited(
        SHORT, scale(["acce_x", "acce_y", "acce_z", "grav_x", "grav_y", "grav_z"], 1 / G))))
    write("csv/pos-in-mm.csv", csv_text(edited(SHORT, scale(["pos_x", "pos_y", "pos_z"], 1000))))
    # gzip: the reference compressed (it reads), and cut in half (it does not).
    packed = gzip.compress(csv_text(full).encode(), mtime=0)
    write("csv/ok.csv.gz", packed)
    write("csv/cut.csv.gz", packed[: len(packed) // 2])
    # Only the gzip magic number.
    write("csv/magic-only.csv.gz", b"\x1f\x8b")
    # A list per mutated recording, for `train` and `eval` (which read recordings listed).
    for name in sorted(os.listdir(os.path.join(HERE, "csv"))):
        write(f"lists/csv/{name}.txt", f"../../csv/{name},Texting\n")


def plain_files():
    short = rows(SHORT)
    def plain(rs, declared=None):
        body = "".join("\t".join(r[1:]) + "\n" for r in rs)
        return f"{len(rs) if declared is None else declared} 27\n" + body
    write("plain/ok/data_plain.txt", plain(short))
    text = plain(short)
    write("plain/truncated/data_plain.txt", text[: text.rindex("\t") + 3])
    write("plain/more-rows-declared/data_plain.txt", plain(short, SHORT + 1))
    write("plain/wrong-width/data_plain.txt", plain(short).replace(" 27\n", " 26\n", 1))
    write("plain/nan-gyro/data_plain.txt", plain(edited(SHORT, set_cell(4, "gyro_x", "nan"))))


def raw_folders():
    """RIDI raw recorder folders without pose.txt: a 200 Hz timeline, no ground truth."""
    n = 40

    def stream(header, values):
        out = [f"# {header}\n"]
        for i in range(n):
            out.append(f"{T0_NS + i * STEP_NS} {values(i)}\n")
        return "".join(out)

    def files(gyro_unit=1.0):
        def q(i):
            yaw = YAW_RATE * i * STEP_NS / 1e9
            return f"0 0 {num(math.sin(yaw / 2))} {num(math.cos(yaw / 2))}"
        return {
            "gyro.txt": stream("t x y z", lambda i: f"0 0 {num(YAW_RATE * gyro_unit)}"),
            "acce.txt": stream("t x y z", lambda i: f"0 0 {num(G)}"),
            "linacce.txt": stream("t x y z", lambda i: "0 0 0"),
            "gravity.txt": stream("t x y z", lambda i: f"0 0 {num(G)}"),
            "orientation.txt": stream("t x y z w", q),
        }

    for name, content in files().items():
        write(f"raw/ok/{name}", content)
        if name != "gyro.txt":
            write(f"raw/missing-gyro/{name}", content)
    for name, content in files(180 / math.pi).items():
        write(f"raw/gyro-deg/{name}", content)
    for name, content in files().items():
        if name == "acce.txt":
            lines = content.splitlines(keepends=True)
            lines[31] = lines[31].replace(f" {num(G)}", " nan")
            content = "".join(lines)
        write(f"raw/nan-acce/{name}", content)


def ilc_files():
    head = "#\tSiteID:5a0546857ecc773753327266\tFloorId:B1\n#\tstartTime:1574559495000\n"
    records = []
    for k in range(3):
        ms = 1574559495000 + 20 * k
        records += [
            f"{ms}\tTYPE_ACCELEROMETER\t-0.6\t1.8\t9.8\t2\n",
            f"{ms}\tTYPE_GYROSCOPE\t-0.3\t-0.07\t0.09\t3\n",
            f"{ms}\tTYPE_MAGNETIC_FIELD\t29.7\t6.4\t-30.0\t3\n",
            f"{ms}\tTYPE_ROTATION_VECTOR\t0.06\t0.07\t0.57\t3\n",
        ]
    records.insert(0, "1574559495000\tTYPE_WAYPOINT\t81.3\t93.3\n")
    records.append("1574559495040\tTYPE_WAYPOINT\t81.4\t93.2\n")
    text = head + "".join(records)
    write("ilc/nan-gyro.txt", text.replace("-0.07", "nan", 1))
    write("ilc/truncated.txt", text[: text.rindex("\t") + 3])
    write("ilc/unknown-field-count.txt", text.replace("\t-0.07\t0.09\t3\n", "\t-0.07\n", 1))


def ronin_folders(rng):
    """RoNIN sequence folders whose `info.json` is sound (the fields RoNIN's loader reads) and
    whose `data.hdf5` is not; the test cuts a real one (ridi-data's fixture) at test time."""
    info = (
        '{"type": "annotated", "length": 1.5, "device": "asus4", '
        '"imu_reference_time": 1.5e+18, "tango_reference_time": 1.5e+18, '
        '"imu_init_gyro_bias": [0.012, -0.021, 0.007], "imu_end_gyro_bias": [0.013, -0.02, 0.008], '
        '"imu_acce_bias": [0.11, -0.07, 0.23], "imu_acce_scale": [1.01, 0.995, 1.003], '
        '"start_calibration": [0.9, 0.0766, -0.1915, 0.383], '
        '"end_calibration": [0.9, 0.0766, -0.1915, 0.383], "imu_time_offset": 0.0, '
        '"align_tango_to_body": [1.0, 0.0, 0.0, 0.0], "gyro_integration_error": 7.5, '
        '"grv_ori_error": 3.25, "ekf_ori_error": 4.0, "start_frame": 0}\n'
    )
    write("ronin/garbage/data.hdf5", bytes(rng.randrange(256) for _ in range(512)))
    write("ronin/garbage/info.json", info)
    # The HDF5 signature and a superblock cut short.
    write("ronin/cut-superblock/data.hdf5", b"\x89HDF\r\n\x1a\n\x00\x00\x00\x00\x00\x08\x08\x00")
    write("ronin/cut-superblock/info.json", info)
    write("ronin/empty/data.hdf5", b"")
    write("ronin/empty/info.json", info)
    # The info file cut short (the data file does not matter: info.json is read first).
    write("ronin/info-cut/data.hdf5", b"\x89HDF\r\n\x1a\n")
    write("ronin/info-cut/info.json", info[:100])


MAGIC = b"RIDIREG\0"


def header(version, length, crc):
    return MAGIC + struct.pack("<IQI", version, length, crc)


def model(payload, version=7, length=None, crc=None):
    return header(version, len(payload) if length is None else length,
                  zlib.crc32(payload) if crc is None else crc) + payload


def model_files(rng):
    """Model files damaged each way the codec checks (crates/ridi-regress/src/model_file.rs):
    magic, version, declared length against the file size, CRC32 of the payload, and a payload
    that passes its checksum yet does not decode."""
    payload = bytes(rng.randrange(256) for _ in range(1000))
    write("model/empty.ridi", b"")
    write("model/text.ridi", b"not a model at all\n")
    write("model/magic-prefix.ridi", MAGIC[:5])
    write("model/header-cut.ridi", model(payload)[:20])
    write("model/header-only.ridi", model(payload)[:24])
    write("model/half.ridi", model(payload)[:24 + 500])
    write("model/bad-magic.ridi", b"RIDIREX\0" + model(payload)[8:])
    write("model/future-version.ridi", model(payload, version=99))
    write("model/old-version.ridi", model(payload, version=6))
    write("model/version-zero.ridi", model(payload, version=0))
    write("model/length-too-long.ridi", model(payload, length=len(payload) + 1))
    write("model/length-too-short.ridi", model(payload, length=len(payload) - 1))
    write("model/length-huge.ridi", model(payload, length=(1 << 64) - 1))
    flipped = bytearray(model(payload))
    flipped[24 + 321] ^= 0x40
    write("model/flipped-byte.ridi", bytes(flipped))
    # Well-formed headers over payloads that pass their checksum yet are no model.
    write("model/garbage-payload.ridi", model(payload))
    write("model/zero-payload.ridi", model(b""))
    write("model/one-byte-payload.ridi", model(b"\x00"))
    write("model/ff-payload.ridi", model(b"\xff" * 64))
    # Version 8 (Nystrom) starts with a kind tag: 1 is an earlier build's, 9 unknown.
    write("model/v8-kind1.ridi", model(b"\x01" + payload[:100], version=8))
    write("model/v8-kind9.ridi", model(b"\x09" + payload[:100], version=8))
    # Not a `.ridi` name, but starting like a model: judged as one by `inspect`.
    write("model/looks-like-a-model.bin", model(payload)[:12])


def lists():
    ok = "../ok/processed/data.csv"
    write("lists/ok.txt", f"# the reference walk\n{ok},Texting\n")
    write("lists/empty.txt", "")
    write("lists/comments-only.txt", "# nothing listed\n\n   \n# still nothing\n")
    # A path starting with `#` is a comment: nothing listed.
    write("lists/hash-entry.txt", "#walk,Texting\n")
    write("lists/comma-entry.txt", f"{ok},Tex,ting\n")
    # A line break inside a path: two lines, `../ok/proc` a path that does not exist.
    write("lists/newline-entry.txt", f"{ok[:10]}\n{ok[10:]},Texting\n")
    write("lists/duplicate.txt", f"{ok},Texting\n# again\n{ok},Texting\n")
    write("lists/duplicate-other-path.txt", f"{ok},Texting\n../ok/,Texting\n")
    write("lists/missing-entry.txt", f"{ok},Texting\n../nowhere/data.csv,Texting\n")
    write("lists/placement-space.txt", f"{ok},Front Pocket\n")
    write("lists/empty-path.txt", ",Texting\n")
    write("lists/binary.txt", b"\x00\x01\x02\xff\xfe\n")
    write("lists/control-char.txt", f"{ok}\x1b[2J,Texting\n")
    write("lists/crlf.txt", f"{ok},Texting\r\n")
    write("lists/no-final-newline.txt", f"{ok},Texting")
    write("lists/list.gz", gzip.compress(f"{ok},Texting\n".encode(), mtime=0))
    write("lists/cut.gz", gzip.compress(f"{ok},Texting\n".encode() * 4, mtime=0)[:20])


def demo_data():
    """A `ridi demo --data` folder whose held-out list is its training list."""
    write("demo/list_train.txt", "../ok,Texting\n")
    write("demo/list_test.txt", "# the training run again\n../ok,Texting\n")


def awkward_names():
    """Sequence folders whose names a list line cannot hold (`ridi convert` refuses them).
    Names with control characters are made by the test: a checkout cannot hold them
    everywhere."""
    short = csv_text(rows(SHORT))
    for name in ["#hash", "a,b"]:
        write(f"names/{name}/processed/data.csv", short)


def main():
    for out in OUTPUTS:
        shutil.rmtree(os.path.join(HERE, out), ignore_errors=True)
    rng = random.Random(20240229)
    processed_csvs(rng)
    plain_files()
    raw_folders()
    ilc_files()
    ronin_folders(rng)
    model_files(rng)
    lists()
    demo_data()
    awkward_names()


if __name__ == "__main__":
    main()
