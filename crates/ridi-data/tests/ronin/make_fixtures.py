#!/usr/bin/env python3
"""Writes the RoNIN-layout test fixtures of ridi-data's RoNIN reader (tests/ronin.rs).

Run by hand, its output is committed (the tests need no Python):

    python3 -m venv /tmp/h5 && /tmp/h5/bin/pip install h5py numpy
    /tmp/h5/bin/python crates/ridi-data/tests/ronin/make_fixtures.py

Each sequence folder holds `data.hdf5` and `info.json` as RoNIN's `compile_dataset_h5.py`
writes them (h5py's defaults: contiguous, unfiltered float64 datasets; groups `synced`, `pose`,
`raw`). The recording is synthetic but physically consistent: a phone turning about the
vertical while tilted, its gyro and accelerometer distorted by the biases and scales that
`info.json` states, and a body-mounted Tango walking a curve.

`expected.json` holds what RoNIN's own loader (`GlobSpeedSequence.load` and
`select_orientation_source`, source/data_glob_speed.py and source/data_utils.py of
github.com/Sachini/ronin) computes from each variant, with numpy, in plain quaternion
arithmetic (numpy-quaternion's Hamilton product, written out).
"""

import json
import os
import shutil

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
RATE = 200.0
G = 9.80665


def qmul(a, b):
    """Hamilton product of (..., 4) arrays in w, x, y, z order."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack([
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ], axis=-1)


def qconj(q):
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def axis_angle(axis, angle):
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    angle = np.asarray(angle, dtype=float)
    half = angle / 2.0
    return np.concatenate([np.cos(half)[..., None], np.sin(half)[..., None] * axis], axis=-1)


def rotate(q, v):
    """q v q* for vectors v (..., 3)."""
    vq = np.concatenate([np.zeros(v.shape[:-1] + (1,)), v], axis=-1)
    return qmul(qmul(q, vq), qconj(q))[..., 1:]


def recording(n, seed):
    rng = np.random.default_rng(seed)
    t0 = 1234.5
    time = t0 + np.arange(n) / RATE
    t = time - t0
    # World-from-device: heading psi(t) about world z, after a constant tilt.
    psi = 0.4 + 0.6 * t + 0.3 * np.sin(2.0 * t)
    dpsi = 0.6 + 0.6 * np.cos(2.0 * t)
    tilt = axis_angle([1.0, 0.3, 0.0], 1.2)
    game_rv = qmul(axis_angle([0.0, 0.0, 1.0], psi), np.broadcast_to(tilt, (n, 4)))
    # Body rate: tilt* (0, 0, dpsi).
    z = np.zeros((n, 3))
    z[:, 2] = dpsi
    gyro_true = rotate(np.broadcast_to(qconj(tilt), (n, 4)), z)
    up = np.broadcast_to(np.array([0.0, 0.0, G]), (n, 3))
    grav = rotate(qconj(game_rv), up)
    linacce = np.stack([1.2 * np.sin(11.0 * t), 0.8 * np.cos(11.0 * t + 0.5),
                        0.6 * np.sin(5.0 * t)], axis=1)
    acce_true = grav + linacce
    gyro_bias = np.array([0.012, -0.021, 0.007])
    acce_bias = np.array([0.11, -0.07, 0.23])
    acce_scale = np.array([1.01, 0.995, 1.003])
    gyro_uncalib = gyro_true + gyro_bias + 1e-4 * rng.standard_normal((n, 3))
    acce = acce_true / acce_scale + acce_bias
    magnet = np.stack([20.0 + np.sin(t), -5.0 + 0 * t, -40.0 + np.cos(t)], axis=1)
    # Tango: walks a curve at about 1.2 m/s; its orientation relates to the phone's through
    # start_calibration (rot_imu_to_tango) and a heading offset of its world.
    heading = 0.3 * t
    vel = np.stack([1.2 * np.cos(heading), 1.2 * np.sin(heading), 0.05 * np.cos(9.0 * t)], axis=1)
    tango_pos = np.array([2.0, -1.0, 0.5]) + np.cumsum(vel, axis=0) / RATE
    calib = axis_angle([0.2, -0.5, 1.0], 0.9)
    world_yaw = axis_angle([0.0, 0.0, 1.0], -1.1)
    tango_ori = qmul(qmul(np.broadcast_to(world_yaw, (n, 4)), game_rv),
                     np.broadcast_to(qconj(calib), (n, 4)))
    # An EKF estimate in another world (turned about z), drifting slowly.
    ekf_ori = qmul(axis_angle([0.0, 0.0, 1.0], 0.7 + 0.01 * t), game_rv)
    info = {
        "type": "annotated",
        "length": float(time[-1] - time[0]),
        "date": "01/02/19",
        "device": "asus4",
        "imu_reference_time": 1.5e18,
        "tango_reference_time": 1.5e18,
        "imu_init_gyro_bias": gyro_bias.tolist(),
        "imu_end_gyro_bias": (gyro_bias + 0.001).tolist(),
        "imu_acce_bias": acce_bias.tolist(),
        "imu_acce_scale": acce_scale.tolist(),
        "gyro_integration_error": 7.5,
        "grv_ori_error": 3.25,
        "ekf_ori_error": 4.0,
        "start_calibration": calib.tolist(),
        "end_calibration": calib.tolist(),
        "imu_time_offset": 0.0,
        "align_tango_to_body": [1.0, 0.0, 0.0, 0.0],
        "start_frame": 20,
    }
    synced = {
        "time": time,
        "gyro_uncalib": gyro_uncalib,
        "gyro": gyro_uncalib - gyro_bias,
        "acce": acce,
        "linacce": linacce,
        "grav": grav,
        "game_rv": game_rv,
        "rv": game_rv,
        "magnet": magnet,
    }
    pose = {"tango_pos": tango_pos, "tango_ori": tango_ori, "ekf_ori": ekf_ori}
    return synced, pose, info


def write_h5(path, synced, pose, libver="earliest", raw=True, tweak=None):
    with h5py.File(path, "w", libver=libver) as f:
        if raw:
            # A little of what RoNIN's files hold besides: raw streams with their timestamps
            # and a variable-length string dataset (the WiFi addresses).
            f.create_dataset("raw/imu/gyro", data=np.c_[synced["time"][:5], synced["gyro"][:5]])
            f.create_dataset("raw/imu/wifi_address", data=np.array(["aa:bb", "cc:dd"], dtype=object),
                             dtype=h5py.special_dtype(vlen=str))
        for k, v in synced.items():
            f.create_dataset("synced/" + k, data=v)
        for k, v in pose.items():
            f.create_dataset("pose/" + k, data=v)
        if tweak is not None:
            tweak(f)


def gyro_integration(ts, gyro, init_q):
    """math_util.gyro_integration of RoNIN, verbatim in effect."""
    out = np.zeros((gyro.shape[0], 4))
    out[0] = init_q
    dts = ts[1:] - ts[:-1]
    for i in range(1, gyro.shape[0]):
        w = gyro[i - 1]
        omega = np.array([[0, -w[0], -w[1], -w[2]],
                          [w[0], 0, w[2], -w[1]],
                          [w[1], -w[2], 0, w[0]],
                          [w[2], w[1], -w[0], 0]]) * 0.5
        out[i] = out[i - 1] + np.dot(omega, out[i - 1]) * dts[i - 1]
        out[i] /= np.linalg.norm(out[i])
    return out


def ronin_load(synced, pose, info, max_ori_error=20.0, grv_only=False):
    """GlobSpeedSequence.load with select_orientation_source, in numpy."""
    names = ["gyro_integration", "game_rv", "ekf"]
    errors = np.array([info["gyro_integration_error"], info["grv_ori_error"], info["ekf_ori_error"]])
    if grv_only or errors[1] < max_ori_error:
        pick = 1
    else:
        pick = int(np.argmin(errors))
    bias = np.array(info["imu_init_gyro_bias"])
    gyro = synced["gyro_uncalib"] - bias
    acce = np.array(info["imu_acce_scale"]) * (synced["acce"] - np.array(info["imu_acce_bias"]))
    ori = [None, synced["game_rv"], pose["ekf_ori"]][pick]
    if pick == 0:
        ori = gyro_integration(synced["time"], gyro, synced["game_rv"][0])
    init_rotor = qmul(qmul(pose["tango_ori"][0], np.array(info["start_calibration"])), qconj(ori[0]))
    ori_q = qmul(np.broadcast_to(init_rotor, ori.shape), ori)
    s = info.get("start_frame", 0)
    return {
        "source": names[pick],
        "source_error": float(errors[pick]),
        "time": synced["time"][s:],
        "gyro": gyro[s:],
        "acce": acce[s:],
        "orientation": ori_q[s:],
        "position": pose["tango_pos"][s:],
    }


def frames_of(result, frames):
    return {
        "source": result["source"],
        "source_error": result["source_error"],
        "len": int(result["time"].shape[0]),
        "frames": [
            {
                "index": i,
                "time": float(result["time"][i]),
                "gyro": result["gyro"][i].tolist(),
                "acce": result["acce"][i].tolist(),
                "orientation_wxyz": result["orientation"][i].tolist(),
                "position": result["position"][i].tolist(),
            }
            for i in frames
        ],
    }


def folder(name):
    path = os.path.join(HERE, name)
    if os.path.isdir(path):
        shutil.rmtree(path)
    os.makedirs(path)
    return path


def write_info(path, info):
    with open(path, "w") as f:
        json.dump(info, f, indent=1)


def main():
    # The valid sequence, 1.5 s: game rotation vector chosen (grv_ori_error 3.25 < 20).
    n = 300
    synced, pose, info = recording(n, seed=1)
    path = folder("a000_1")
    write_h5(os.path.join(path, "data.hdf5"), synced, pose)
    write_info(os.path.join(path, "info.json"), info)

    # The orientation-source variants, as info.json files beside the one data.hdf5 (the tests
    # assemble each folder): EKF (grv over the bound, ekf the smallest), gyro integration
    # (grv over the bound, gyro the smallest), game rotation vector forced by grv_only.
    variants = {}
    info_ekf = dict(info, grv_ori_error=25.0, ekf_ori_error=4.0, gyro_integration_error=7.5)
    info_gyro = dict(info, grv_ori_error=21.0, ekf_ori_error=30.0, gyro_integration_error=2.0)
    path = folder("variants")
    write_info(os.path.join(path, "info_ekf.json"), info_ekf)
    write_info(os.path.join(path, "info_gyro.json"), info_gyro)
    m = n - info["start_frame"]
    frames = [0, 1, m // 2, m - 1]
    variants["a000_1"] = frames_of(ronin_load(synced, pose, info), frames)
    variants["info_ekf"] = frames_of(ronin_load(synced, pose, info_ekf), frames)
    variants["info_gyro"] = frames_of(ronin_load(synced, pose, info_gyro), frames)
    variants["info_ekf_grv_only"] = frames_of(ronin_load(synced, pose, info_ekf, grv_only=True),
                                              frames)
    with open(os.path.join(path, "expected.json"), "w") as f:
        json.dump(variants, f, indent=1)

    # Part of the layout with h5py's libver="latest": superblock 3, version 2 object headers,
    # groups of up to 8 links as link messages; a group of 9 (`dense`) keeps its links in a
    # fractal heap, which the reader refuses with an error.
    small_synced, small_pose, _ = recording(40, seed=2)
    small_synced = {k: small_synced[k] for k in ["time", "acce", "game_rv"]}
    small_pose = {"tango_pos": small_pose["tango_pos"]}

    def dense(f):
        for k in range(9):
            f.create_dataset("dense/d%d" % k, data=np.arange(3.0) + k)

    write_h5(os.path.join(path, "latest.hdf5"), small_synced, small_pose, libver="latest",
             raw=False, tweak=dense)

    # Bad input, each a small sequence folder with one thing wrong.
    def bad(name, tweak=None, info_edit=None, drop=None):
        s, p, i = recording(40, seed=3)
        i = dict(i, start_frame=0)
        if drop is not None:
            group, key = drop.split("/")
            del (s if group == "synced" else p)[key]
        dst = folder(os.path.join("bad", name))
        write_h5(os.path.join(dst, "data.hdf5"), s, p, raw=False, tweak=tweak)
        if info_edit is not None:
            info_edit(i)
        write_info(os.path.join(dst, "info.json"), i)

    def replace(name, make):
        def tweak(f):
            data = f[name][()]
            del f[name]
            make(f, name, data)
        return tweak

    bad("missing_dataset", drop="synced/acce")
    bad("wrong_shape", tweak=replace("synced/acce", lambda f, k, d: f.create_dataset(k, data=d[:, :2])))
    bad("wrong_type", tweak=replace("synced/gyro_uncalib",
                                    lambda f, k, d: f.create_dataset(k, data=(d * 1000).astype(np.int32))))
    bad("wrong_length", tweak=replace("pose/tango_pos", lambda f, k, d: f.create_dataset(k, data=d[:-1])))
    bad("chunked", tweak=replace("synced/game_rv",
                                 lambda f, k, d: f.create_dataset(k, data=d, compression="gzip")))
    bad("info_without_field", info_edit=lambda i: i.pop("imu_acce_bias"))
    print("wrote fixtures under", HERE)


if __name__ == "__main__":
    main()
