#!/usr/bin/python3
"""Writes the IDR camera files of test_idr_cameras.cpp with numpy itself (np.savez and
np.savez_compressed), so that the reader is tested on the archives numpy makes, zip64 fields and
deflated entries included:

  cameras_deflated.npz   np.savez_compressed, float64, NeuS's entries (world_mat_I, scale_mat_I,
                         camera_mat_I, world_mat_inv_I, scale_mat_inv_I); world_mat_1 in Fortran
                         order and scaled by -2.5 (a P's scale and sign are free)
  cameras_float32.npz    np.savez (stored), the same matrices as float32, world_mat_I and
                         scale_mat_I only
  cameras.txt            the same three P as a projection list (17 significant digits)

The object is the sphere of radius 1.5 around (0.1, -0.2, 0.3); three cameras on a ring 4 away
look at its centre. Run with /usr/bin/python3 (numpy) from any directory; deterministic.
"""
import pathlib

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
CENTRE = np.array([0.1, -0.2, 0.3])
RADIUS = 1.5
K = np.array([[600.0, 0.0, 319.5], [0.0, 610.0, 239.5], [0.0, 0.0, 1.0]])


def look_at(position, target):
    """Rows: camera x right, y down, z forward (world z up)."""
    z = target - position
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])


def world_mat(i, views=3):
    azimuth = 2.0 * np.pi * i / views
    position = CENTRE + 4.0 * np.array(
        [np.cos(0.3) * np.cos(azimuth), np.cos(0.3) * np.sin(azimuth), np.sin(0.3)])
    R = look_at(position, CENTRE)
    t = -R @ position
    P = np.eye(4)
    P[:3, :] = K @ np.hstack([R, t[:, None]])
    return P


scale_mat = np.diag([RADIUS, RADIUS, RADIUS, 1.0])
scale_mat[:3, 3] = CENTRE
mats = [world_mat(i) for i in range(3)]
mats[1] = np.asfortranarray(-2.5 * mats[1])
mats[1][3] = [0.0, 0.0, 0.0, 1.0]  # IDR's last row stays 0 0 0 1 whatever P's scale

entries = {}
for i, m in enumerate(mats):
    camera_mat = np.eye(4)
    camera_mat[:3, :3] = K
    entries[f"world_mat_{i}"] = m
    entries[f"scale_mat_{i}"] = scale_mat
    entries[f"camera_mat_{i}"] = camera_mat
    entries[f"world_mat_inv_{i}"] = np.linalg.inv(m)
    entries[f"scale_mat_inv_{i}"] = np.linalg.inv(scale_mat)
np.savez_compressed(HERE / "cameras_deflated.npz", **entries)
np.savez(HERE / "cameras_float32.npz",
         **{name: m.astype(np.float32) for name, m in entries.items()
            if name.startswith(("world_mat_", "scale_mat_")) and "_inv_" not in name})
with open(HERE / "cameras.txt", "w") as out:
    out.write("# the world_mat_I of cameras_deflated.npz, top 3x4 rows\n")
    for m in mats:
        out.write(" ".join(repr(float(x)) for x in m[:3].reshape(-1)) + "\n")
