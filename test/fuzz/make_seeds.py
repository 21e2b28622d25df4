#!/usr/bin/python3
"""Writes the generated seed inputs of the fuzz harnesses into test/fuzz/corpus/<harness>/.

Small, valid files of each format (plus a few edge cases), made from the formats as the readers
and writers in src/core define them: readMiddleburyPar / writeMiddleburyPar (dataset.cpp),
readProjectionList, readHomography (evaluation.cpp, Oxford's H1to2p layout), readPfm / writePfm
(io/pfm.cpp), readPly / writePly (io/ply.cpp), readIdrCameraMatrices / writeIdrCameras (io/idr.cpp,
numpy .npz archives), and the byte layout of fuzz_bounding_box.cpp.
Not written here: the copies of ../shared/repro's files (par_c_1e39.txt, par_t_1e307.txt,
pfm_4GiB_header.pfm) and the regress_* files, fixed findings kept as regression inputs
(test/fuzz/findings/README.md). Deterministic: running it again gives the same bytes.
"""
import io
import math
import pathlib
import struct
import zipfile

CORPUS = pathlib.Path(__file__).resolve().parent / "corpus"


# ---- a ring of cameras looking at the origin, the scene renderer's conventions (scene.cpp) ------
def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalized(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def look_at(centre, target=(0.0, 0.0, 0.0)):
    """Rows: camera x right, y down, z forward."""
    z = normalized(sub(target, centre))
    x = normalized(cross(z, [0.0, 0.0, 1.0]))
    y = cross(z, x)
    return [x, y, z]


def mat_vec(m, v):
    return [sum(m[r][c] * v[c] for c in range(3)) for r in range(3)]


def ring_camera(i, views, distance=2.0, elevation=0.4, focal=300.0, size=(320, 240)):
    azimuth = 2.0 * math.pi * i / views
    centre = [distance * math.cos(elevation) * math.cos(azimuth),
              distance * math.cos(elevation) * math.sin(azimuth), distance * math.sin(elevation)]
    R = look_at(centre)
    t = [-x for x in mat_vec(R, centre)]
    K = [[focal, 0.0, 0.5 * (size[0] - 1)], [0.0, focal, 0.5 * (size[1] - 1)], [0.0, 0.0, 1.0]]
    return K, R, t


def quaternion(R):
    """(w, x, y, z) of a rotation matrix (Shepperd's method)."""
    trace = R[0][0] + R[1][1] + R[2][2]
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        return [0.25 * s, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s, (R[1][0] - R[0][1]) / s]
    i = max(range(3), key=lambda k: R[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + R[i][i] - R[j][j] - R[k][k])
    q = [0.0] * 4
    q[0] = (R[k][j] - R[j][k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (R[j][i] + R[i][j]) / s
    q[1 + k] = (R[k][i] + R[i][k]) / s
    return q


def fmt(x):
    return repr(float(x))


def write(harness, name, data):
    path = CORPUS / harness / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    assert len(data) < 4096, (path, len(data))
    path.write_bytes(data)


# ---- Middlebury par --------------------------------------------------------------------------
def par_line(name, K, R, t):
    numbers = [x for row in K for x in row] + [x for row in R for x in row] + list(t)
    return name + " " + " ".join(fmt(x) for x in numbers) + "\n"


def par_file(views, extra=""):
    lines = [par_line(f"view_{i:04d}.png", *ring_camera(i, views)) for i in range(views)]
    return f"{views}\n" + extra + "".join(lines)


write("fuzz_middlebury_par", "ring1.txt", par_file(1))
write("fuzz_middlebury_par", "ring3.txt", par_file(3))
write("fuzz_middlebury_par", "ring3_comments.txt",
      "# a comment line\n" + par_file(3, extra="\n# blank lines and comments are skipped\n\n"))
# The dino files' layout: fixed-point numbers, a skewless K with different focal lengths.
write("fuzz_middlebury_par", "dino_layout.txt",
      "1\nimg0001.png 3310.400000 0.000000 316.730000 0.000000 3325.500000 200.550000 "
      "0.000000 0.000000 1.000000 1 0 0 0 1 0 0 0 1 -0.05 0.02 0.6\n")

# ---- projection list ---------------------------------------------------------------------------
def projection(K, R, t):
    Rt = [R[r] + [t[r]] for r in range(3)]
    return [[sum(K[r][k] * Rt[k][c] for k in range(3)) for c in range(4)] for r in range(3)]


def projection_line(name, P):
    return (name + " " if name else "") + " ".join(fmt(x) for row in P for x in row) + "\n"


write("fuzz_projection_list", "named3.txt",
      "".join(projection_line(f"view_{i:04d}.png", projection(*ring_camera(i, 3)))
              for i in range(3)))
write("fuzz_projection_list", "unnamed2_comments.txt",
      "# P = K [R | t], row major\n\n" +
      "".join(projection_line("", projection(*ring_camera(i, 2))) for i in range(2)))
write("fuzz_projection_list", "scaled.txt",
      projection_line("a.png", [[-2 * x for x in row] for row in projection(*ring_camera(0, 4))]))

# ---- homography (9 numbers, any white space) -----------------------------------------------
write("fuzz_homography", "identity", "1 0 0\n0 1 0\n0 0 1\n")
write("fuzz_homography", "oxford_layout",
      "   8.5e-01   3.0e-01  -3.5e+01\n  -1.5e-01   9.0e-01   1.5e+02\n"
      "   2.0e-04  -1.5e-05   1.0e+00\n")
write("fuzz_homography", "one_line", "0.5 0 10 0 0.5 -20 0 0 1")

# ---- PFM -------------------------------------------------------------------------------------------
def pfm(width, height, values, little_endian=True):
    header = f"Pf\n{width} {height}\n{'-1' if little_endian else '1'}\n".encode()
    return header + struct.pack(("<" if little_endian else ">") + "f" * len(values), *values)


write("fuzz_pfm", "3x2_little.pfm", pfm(3, 2, [0.5, 1.0, 1.5, 2.0, 2.5, 3.0]))
write("fuzz_pfm", "2x2_big_inf.pfm", pfm(2, 2, [float("inf"), 1.25, 0.0, -4.0], False))
write("fuzz_pfm", "1x1.pfm", pfm(1, 1, [7.0]))

# ---- PLY (writePly's binary little-endian layout) ------------------------------------------
def ply(vertices, faces, comment=None):
    header = "ply\nformat binary_little_endian 1.0\n"
    if comment:
        header += f"comment {comment}\n"
    header += (f"element vertex {len(vertices)}\nproperty float x\nproperty float y\n"
               f"property float z\nelement face {len(faces)}\n"
               "property list uchar int vertex_indices\nend_header\n")
    body = b"".join(struct.pack("<fff", *v) for v in vertices)
    body += b"".join(struct.pack("<Biii", 3, *f) for f in faces)
    return header.encode() + body


tetrahedron = ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)],
               [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
write("fuzz_ply", "tetrahedron.ply", ply(*tetrahedron))
write("fuzz_ply", "tetrahedron_comment.ply", ply(*tetrahedron, comment="written by sift_hull"))
write("fuzz_ply", "empty.ply", ply([], []))
write("fuzz_ply", "vertices_only.ply", ply([(0.5, -1.5, 2.0), (1e30, -0.0, 1e-40)], []))

# ---- hullBoundingBox input (fuzz_bounding_box.cpp's layout) ------------------------------
def sphere_bounds(K, R, t, radius=0.5):
    """Pixel bounds of the projection of the sphere at the origin (conservative square)."""
    centre_cam = t  # the origin in camera coordinates
    depth = centre_cam[2]
    u = K[0][0] * centre_cam[0] / depth + K[0][2]
    v = K[1][1] * centre_cam[1] / depth + K[1][2]
    r = K[0][0] * radius / math.sqrt(depth * depth - radius * radius)
    return [u - r, u + r, v - r, v + r]


def box_view(K, R, t, bounds=None, flags=0b1111):
    bounds = bounds if bounds is not None else sphere_bounds(K, R, t)
    numbers = [K[0][0], K[0][1], K[0][2], K[1][1], K[1][2], K[2][2]] + quaternion(R) + list(t)
    return struct.pack("<17d", *(numbers + bounds)) + bytes([flags])


def box_input(cameras, **kwargs):
    return bytes([len(cameras) - 2]) + b"".join(box_view(*c, **kwargs) for c in cameras)


ring4 = [ring_camera(i, 4) for i in range(4)]
ring8 = [ring_camera(i, 8) for i in range(8)]
write("fuzz_bounding_box", "ring2", box_input([ring_camera(0, 4), ring_camera(1, 4)]))
write("fuzz_bounding_box", "ring4", box_input(ring4))
write("fuzz_bounding_box", "ring8", box_input(ring8))
write("fuzz_bounding_box", "ring4_open_sides", box_input(ring4, flags=0b0101))
# The same as ring4 with one camera's t_z = 1e307 (as ../shared/repro/par_t_1e307.txt).
far = list(ring4)
far[1] = (far[1][0], far[1][1], [far[1][2][0], far[1][2][1], 1e307])
write("fuzz_bounding_box", "ring4_t_1e307", box_input(far))
# One camera centre at z = 1e39 (as ../shared/repro/par_c_1e39.txt): t = -R c.
centre = [0.0, 0.0, 1e39]
far = list(ring4)
far[2] = (far[2][0], far[2][1], [-x for x in mat_vec(far[2][1], centre)])
write("fuzz_bounding_box", "ring4_c_1e39", box_input(far))
# Tiny focal length and subnormal bounds.
tiny = [([[1e-300, 0, 0], [0, 1e-300, 0], [0, 0, 1]], R, t) for K, R, t in ring4]
write("fuzz_bounding_box", "ring4_tiny", box_input(tiny, bounds=[-5e-324, 5e-324, -1e-310, 1e-310]))


# ---- COLMAP binary models: first byte 0 for cameras.bin, 1 for images.bin -----------------------
def colmap_cameras(models):
    data = struct.pack("<Q", len(models))
    for camera_id, (model_id, params) in enumerate(models, start=1):
        data += struct.pack("<iiQQ", camera_id, model_id, 640, 480)
        data += struct.pack(f"<{len(params)}d", *params)
    return b"\x00" + data


def colmap_images(views, points=2):
    data = struct.pack("<Q", len(views))
    for image_id, (K, R, t) in enumerate(views, start=1):
        data += struct.pack("<I", image_id) + struct.pack("<4d", *quaternion(R))
        data += struct.pack("<3d", *t) + struct.pack("<I", 1)
        data += f"view_{image_id:04d}.png".encode() + b"\x00" + struct.pack("<Q", points)
        data += b"".join(struct.pack("<ddQ", 10.0 * p, 20.0, p) for p in range(points))
    return b"\x01" + data


write("fuzz_colmap_binary", "pinhole_opencv", colmap_cameras(
    [(1, [500, 500, 320, 240]), (4, [500, 500, 320, 240, -0.1, 0.01, 0.001, 0.002])]))
write("fuzz_colmap_binary", "every_model", colmap_cameras(
    [(0, [500, 320, 240]), (2, [500, 320, 240, 0.1]), (3, [500, 320, 240, 0.1, 0.2]),
     (6, [500, 500, 320, 240, 0.1, 0.2, 0.0, 0.0, 0.3, 0.0, 0.0, 0.0])]))
write("fuzz_colmap_binary", "images_ring4", colmap_images([ring_camera(i, 4) for i in range(4)]))
write("fuzz_colmap_binary", "images_no_points", colmap_images([ring_camera(0, 2)], points=0))


# ---- LLFF poses_bounds.npy ----------------------------------------------------------------------
def npy(rows, fortran=False, version=1):
    header = "{'descr': '<f8', 'fortran_order': %s, 'shape': (%d, 17), }" % (
        "True" if fortran else "False", len(rows))
    fixed = 10 if version == 1 else 12
    header += " " * ((64 - (fixed + len(header) + 1) % 64) % 64) + "\n"
    length = struct.pack("<H", len(header)) if version == 1 else struct.pack("<I", len(header))
    values = [x for row in rows for x in row]
    if fortran:
        values = [rows[r][c] for c in range(17) for r in range(len(rows))]
    return b"\x93NUMPY" + bytes([version, 0]) + length + header.encode() + struct.pack(
        f"<{len(values)}d", *values)


def llff_row(K, R, t):
    # camera-to-world axes in LLFF's [down, right, backwards] order, centre, [height, width, focal]
    Rt = [[R[c][r] for c in range(3)] for r in range(3)]  # R^T: columns are the camera axes
    centre = [-x for x in mat_vec(Rt, t)]
    columns = [[Rt[r][1] for r in range(3)], [Rt[r][0] for r in range(3)],
               [-Rt[r][2] for r in range(3)], centre, [240.0, 320.0, K[0][0]]]
    return [columns[c][r] for r in range(3) for c in range(5)] + [0.5, 4.0]


ring3_rows = [llff_row(*ring_camera(i, 3)) for i in range(3)]
write("fuzz_npy", "ring3", npy(ring3_rows))
write("fuzz_npy", "ring3_fortran", npy(ring3_rows, fortran=True))
write("fuzz_npy", "ring2_v2", npy(ring3_rows[:2], version=2))


def nerf_frame(name, centre_z, extra=""):
    return ('{"file_path": "%s", %s"transform_matrix": [[1, 0, 0, 0], [0, -1, 0, 0.1], '
            '[0, 0, -1, %r], [0, 0, 0, 1]]}' % (name, extra, centre_z))


write("fuzz_nerf_transforms", "angle_two_frames",
      ('{"camera_angle_x": 0.69, "w": 64, "h": 48, "frames": [%s, %s]}' %
       (nerf_frame("./train/r_0", -4.0), nerf_frame("./train/r_1", -5.0))).encode())
write("fuzz_nerf_transforms", "instant_ngp_per_frame",
      ('{"fl_x": 50, "fl_y": 51, "cx": 32, "cy": 24, "w": 64, "h": 48, "k1": 0.01, "p1": 0.001, '
       '"frames": [%s]}' % nerf_frame("a.png", -4.0, '"fl_x": 60, "k2": -0.02, ')).encode())


# ---- IDR / NeuS cameras.npz: a zip archive of 4x4 .npy arrays ----------------------------------
def npy_matrix(m, dtype="<f8"):
    header = "{'descr': '%s', 'fortran_order': False, 'shape': (%d, %d), }" % (
        dtype, len(m), len(m[0]))
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    values = [x for row in m for x in row]
    code = "d" if dtype == "<f8" else "f"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + struct.pack(
        f"<{len(values)}{code}", *values)


def world_mat(K, R, t):
    return projection(K, R, t) + [[0.0, 0.0, 0.0, 1.0]]


def npz(entries, compression=zipfile.ZIP_STORED):
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as archive:
        for name, data in entries:
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = compression
            archive.writestr(info, data)
    return out.getvalue()


unit_scale = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0],
              [0.0, 0.0, 0.0, 1.0]]
write("fuzz_idr_cameras", "ring3_stored.npz",
      npz([(f"world_mat_{i}.npy", npy_matrix(world_mat(*ring_camera(i, 3)))) for i in range(3)] +
          [("scale_mat_0.npy", npy_matrix(unit_scale))]))
write("fuzz_idr_cameras", "ring4_deflated.npz",
      npz([(f"{kind}_{i}.npy", npy_matrix(world_mat(*ring_camera(i, 4)) if kind == "world_mat"
                                          else unit_scale))
           for i in range(4) for kind in ("world_mat", "scale_mat", "camera_mat")],
          zipfile.ZIP_DEFLATED))
write("fuzz_idr_cameras", "ring2_float32_no_scale.npz",
      npz([(f"world_mat_{i}.npy", npy_matrix(world_mat(*ring_camera(i, 2)), "<f4"))
           for i in range(2)]))
