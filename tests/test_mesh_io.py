"""File guards of :func:`igl_hhj.mesh_io.read_mesh` accept every valid file libigl reads
(issue 24, item A): OFF face records that continue on the following lines (libigl
reads OFF faces token by token, as in libigl's tutorial files
``inspired_mesh_quads_*.off``) and OBJ/OFF/PLY files that start with a UTF-8 byte
order mark.  The memory / truncation guards are tested in test_reliability.py and
test_cli.py (bad files); here the valid files and the bad variants of the new paths."""
from __future__ import annotations

import igl
import numpy as np
import pytest

from igl_hhj import cli, mesh_io
from igl_hhj.surfaces import icosphere

BOM = b"\xef\xbb\xbf"
TRIANGLE_V = [[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]


def _write(tmp_path, name, data):
    path = tmp_path / name
    path.write_bytes(data)
    return path


def test_off_face_record_wrapped_across_lines(tmp_path):
    path = _write(tmp_path, "wrap.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0\n1 2\n")
    V, F, messages = mesh_io.read_mesh(path)
    np.testing.assert_array_equal(V, TRIANGLE_V)
    np.testing.assert_array_equal(F, [[0, 1, 2]])
    assert messages == []
    assert cli.main(["info", str(path)]) == 0


def test_off_wrapped_records_read_as_libigl_reads_them(tmp_path):
    """Every record of a 20k-face sphere over three lines with trailing colours (skipped by
    libigl after the last index), blank lines and comments between the records; a quad
    record like libigl's inspired_mesh_quads files."""
    V, F = icosphere(5)
    body = [" ".join(map(repr, v)) for v in V.tolist()]
    body += [f"3 {a}\n{b}\n\n  {c} 255 0 0 # colour" + ("\n# between records" if i % 7 == 0 else "")
             for i, (a, b, c) in enumerate(F.tolist())]
    path = _write(tmp_path, "sphere.off", ("OFF\n%d %d 0\n" % (len(V), len(F)) + "\n".join(body)
                                           + "\n").encode())
    V2, F2, _ = mesh_io.read_mesh(path)
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_allclose(V2, V, rtol=0, atol=0)
    np.testing.assert_array_equal(F2, igl.read_triangle_mesh(str(path))[1])
    # mixed: one-line records, then a wrapped one, then one-line records again
    mixed = _write(tmp_path, "quads.off", b"OFF\n6 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n2 1 0\n"
                                          b"4 0 1 2 3\n4 1 4\n5 2\n4 0 1 2 3\n")
    V3, F3, _ = mesh_io.read_mesh(mixed)
    np.testing.assert_array_equal(F3, igl.read_triangle_mesh(str(mixed))[1])
    # (libigl's read_triangle_mesh fans the quads into triangles)
    np.testing.assert_array_equal(F3, [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2], [0, 1, 2], [0, 2, 3]])


@pytest.mark.parametrize("faces, match", [
    (b"3 0 # a comment inside the record\n1 2\n", "line 6: face record continues after a comment"),
    (b"3 0\n1 x\n", "line 6: face corner is not a non-negative integer index"),
    (b"3 0\n1\n", "line 6: face line claims more corners than it lists"),
    (b"2000000000 0\n1 2\n", "claims more corners than it lists"),      # libigl: 16 GB, then bad_alloc
    (b"2 0\n1\n", "line 6: face with fewer than 3 corners"),
    (b"x 0\n1 2\n", "line 6: face line does not start with its corner count"),
])
def test_off_bad_wrapped_records_are_one_line_errors(tmp_path, faces, match):
    path = _write(tmp_path, "bad.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n" + faces)
    with pytest.raises(mesh_io.MeshFileError, match=match):
        mesh_io.read_mesh(path)


def test_off_fewer_records_than_declared(tmp_path):
    path = _write(tmp_path, "short.off", b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0\n1 2\n")
    with pytest.raises(mesh_io.MeshFileError, match="declares 2 faces, the file has only 1 face record$"):
        mesh_io.read_mesh(path)


def _ply(fmt):
    head = (f"ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            f"property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            f"end_header\n").encode()
    if fmt == "ascii":
        return head + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
    return head + np.array(TRIANGLE_V, "<f4").tobytes() + b"\x03" + np.arange(3, dtype="<i4").tobytes()


VALID = {"t.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
         "t.off": b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
         "t.ply": _ply("ascii"),
         "t_bin.ply": _ply("binary_little_endian")}


@pytest.mark.parametrize("name", sorted(VALID))
def test_utf8_bom_is_ignored(tmp_path, name, capfd):
    """libigl 2.6 drops the first OBJ line (the first vertex) and rejects the OFF header."""
    path = _write(tmp_path, name, BOM + VALID[name])
    V, F, messages = mesh_io.read_mesh(path)
    np.testing.assert_array_equal(V, TRIANGLE_V)
    np.testing.assert_array_equal(F, [[0, 1, 2]])
    assert messages == []
    assert cli.main(["info", str(path)]) == 0
    assert "warning" not in capfd.readouterr().err
    assert path.read_bytes().startswith(BOM)                      # the input is not touched


@pytest.mark.parametrize("name, data, match", [
    ("only.obj", BOM, "file is empty"),
    ("trunc.off", BOM + b"OFF\n3 1 0\n0 0 0\n1 0 0\n", "truncated"),
    ("zero.obj", BOM + b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4: face uses vertex index 0"),
    ("bad.ply", BOM + _ply("ascii").replace(b"3 0 1 2", b"4 0 1 2"), "face is not a triangle"),
])
def test_utf8_bom_errors_name_the_original_file(tmp_path, name, data, match):
    path = _write(tmp_path, name, data)
    with pytest.raises(mesh_io.MeshFileError, match=match) as info:
        mesh_io.read_mesh(path)
    assert str(info.value).startswith(f"{path}: ") and "igl-hhj-" not in str(info.value)
