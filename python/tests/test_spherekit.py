# The Python module against the command line: the same bytes for param and consistent, the
# same error messages as exceptions, cancellation through the progress callback and Ctrl-C,
# numpy views instead of copies.
import filecmp
import json
import os
import signal
import subprocess
import threading

import numpy as np
import pytest

import spherekit as sk
from conftest import ROOT, cli_error


def test_version_matches_the_program(exe):
    out = subprocess.run([exe, "--version"], capture_output=True, text=True, check=True).stdout
    assert sk.__version__ in out


def test_param_writes_the_cli_bytes(exe, samples, tmp_path):
    mesh_path = str(samples / "sample_a.obj")
    cli_map = tmp_path / "cli.sphere.obj"
    subprocess.run([exe, "param", mesh_path, "-o", str(cli_map), "--quiet"], check=True)

    mesh = sk.read_mesh(mesh_path)
    stages = []
    result = sk.param(mesh, progress=lambda stage, level, fraction: stages.append(stage))
    assert result.flipped_faces == 0
    assert sk.count_flipped_faces(mesh, result.S) == 0
    assert result.S.shape == (mesh.vertices, 3)
    assert np.allclose(np.linalg.norm(result.S, axis=1), 1.0, atol=1e-12)
    assert stages, "the progress callback was never called"
    py_map = tmp_path / "py.sphere.obj"
    sk.write_sphere_map(str(py_map), mesh, result)
    assert filecmp.cmp(cli_map, py_map, shallow=False), "the module's sphere map differs from `spherekit param`'s"

    # And it reads back as the same map; eval measures it as the command line does.
    back = sk.read_sphere_map(str(cli_map), mesh)
    assert np.array_equal(back.S, result.S)
    metrics = sk.eval(mesh, back.S)
    assert metrics.flipped == 0 and metrics.efficiency == pytest.approx(result.efficiency, rel=1e-9)


def test_consistent_writes_the_cli_bytes(exe, samples, tmp_path):
    names = ["sample_a", "sample_b"]  # two members keep it short; the six steps all run
    col = tmp_path / "col"
    subprocess.run([exe, "consistent", "-o", str(col), *[str(samples / f"{n}.obj") for n in names],
                    "--remesh-size", "33", "--effort", "1", "--quiet"], check=True)

    meshes = [sk.read_mesh(str(samples / f"{n}.obj")) for n in names]
    landmarks = [sk.read_landmarks(str(samples / f"{n}.lm.txt"), m.vertices) for n, m in zip(names, meshes)]
    order = [name for name, _ in landmarks[0]]
    features = [[dict(lms)[name] for name in order] for lms in landmarks]
    result = sk.consistent(meshes, features, remesh_size=33, effort=1)
    assert len(result.maps) == len(names)
    for name, mesh, m in zip(names, meshes, result.maps):
        assert m.flipped_faces == 0 and m.max_feature_angle < 1e-9
        out = tmp_path / f"{name}.sphere.obj"
        sk.write_sphere_map(str(out), mesh, m)
        assert filecmp.cmp(col / f"{name}.sphere.obj", out, shallow=False), f"{name}: differs from `spherekit consistent`"
    # features.txt holds F with 17 significant digits: it reads back as exactly the same doubles.
    cli_names, cli_locations = sk.read_sphere_points(str(col / "features.txt"))
    assert cli_names == order
    assert np.array_equal(cli_locations, result.final_locations)
    # Every member's unconstrained efficiency (what the efficiency retry compares against), as
    # collection.json records it; a retried map says so only below the bar.
    manifest = json.loads((col / "collection.json").read_text())
    assert len(result.unconstrained_efficiency) == len(names)
    for entry, u, m in zip(manifest["meshes"], result.unconstrained_efficiency, result.maps):
        assert 0 < u <= 1 and entry["result"]["unconstrained_efficiency"] == u
        assert not m.efficiency_retried or m.first_efficiency < 0.8 * u


def test_errors_are_exceptions_with_the_cli_messages(exe, tmp_path):
    bad = ROOT / "tests" / "data" / "bad"
    # A malformed file: ParseError (an InvalidInput, a ValueError), the program's message.
    code, message = cli_error(exe, "check", str(bad / "obj_truncated.obj"))
    with pytest.raises(sk.ParseError) as e:
        sk.read_mesh(str(bad / "obj_truncated.obj"))
    assert str(e.value) == message and e.value.exit_code == code == 3 and e.value.code == "ParseError"
    assert isinstance(e.value, sk.InvalidInput) and isinstance(e.value, ValueError) and isinstance(e.value, sk.Error)
    # A missing file: IoError (an OSError), exit code 4.
    missing = str(tmp_path / "no_such_mesh.obj")
    code, message = cli_error(exe, "check", missing)
    with pytest.raises(sk.IoError) as e:
        sk.read_mesh(missing)
    assert str(e.value) == message and e.value.exit_code == code == 4 and isinstance(e.value, OSError)
    # A mesh param refuses (genus 1): InvalidInput naming the file, as `spherekit param` says it.
    torus = str(bad / "genus1_torus.obj")
    code, message = cli_error(exe, "param", torus, "-o", str(tmp_path / "t.sphere.obj"))
    with pytest.raises(sk.InvalidInput) as e:
        sk.param(sk.read_mesh(torus))
    assert str(e.value) == message and e.value.exit_code == code == 3
    assert not (tmp_path / "t.sphere.obj").exists()
    # Bad arrays: InvalidArgument (a ValueError).
    with pytest.raises(sk.InvalidArgument):
        sk.Mesh(np.zeros((4, 2)), np.zeros((1, 3), dtype=np.int32))
    with pytest.raises(sk.InvalidArgument):
        sk.geometry_image(sk.read_mesh(str(bad / "octahedron.obj")), np.eye(3), 64)


def test_progress_callback_cancels(samples):
    mesh = sk.read_mesh(str(samples / "sample_b.obj"))
    calls = []

    def stop_at_third(stage, level, fraction):
        calls.append((stage, level, fraction))
        return len(calls) < 3

    with pytest.raises(sk.Cancelled) as e:
        sk.param(mesh, progress=stop_at_third)
    assert len(calls) == 3 and e.value.exit_code == 130
    # An exception in the callback stops the stage and comes out as itself.
    with pytest.raises(ZeroDivisionError):
        sk.param(mesh, progress=lambda stage, level, fraction: 1 / 0)
    # The module is usable afterwards.
    assert sk.param(mesh, effort=0).flipped_faces == 0


def test_ctrl_c_interrupts_a_stage_with_the_gil_released(samples):
    # The callback never asks to stop: only the SIGINT, sent by another thread once the stage
    # is running, can; the library sees it through PyErr_CheckSignals in the progress glue.
    mesh = sk.read_mesh(str(samples / "sample_c.obj"))
    started = threading.Event()
    sender = threading.Thread(target=lambda: started.wait(60) and os.kill(os.getpid(), signal.SIGINT))
    sender.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sk.param(mesh, effort=5, progress=lambda *event: started.set())
    finally:
        started.set()
        sender.join()


def test_arrays_are_views_not_copies(samples):
    mesh = sk.read_mesh(str(samples / "sample_a.obj"))
    V = mesh.V
    assert V.dtype == np.float64 and mesh.F.dtype == np.int32 and not V.flags.owndata
    assert np.shares_memory(V, mesh.V), "two reads of Mesh.V should view the same buffer"
    result = sk.param(mesh, effort=0)
    assert not result.S.flags.owndata and np.shares_memory(result.S, result.S)
    copy = sk.Mesh(V * 2.0, mesh.F)
    assert copy.vertices == mesh.vertices and np.array_equal(copy.V, V * 2.0)


def test_geometry_image_lods_and_cage(exe, samples, tmp_path):
    mesh_path = str(samples / "sample_a.obj")
    mesh = sk.read_mesh(mesh_path)
    result = sk.param(mesh)
    sphere = str(tmp_path / "a.sphere.obj")
    sk.write_sphere_map(sphere, mesh, result)
    image = sk.geometry_image(mesh, result.S, 65)
    assert image.positions.shape == (65, 65, 3) and image.positions.dtype == np.float32
    # The same image `spherekit convert` writes (positions fitted, the default).
    cli_exr = str(tmp_path / "cli.exr")
    subprocess.run([exe, "convert", mesh_path, sphere, "-o", cli_exr, "--size", "65", "--psnr-samples", "0", "--quiet"],
                   check=True)
    cli_image, attributes = sk.read_geometry_image_exr(cli_exr)
    assert np.array_equal(cli_image.positions, image.positions)
    assert np.array_equal(cli_image.face_ids, image.face_ids)
    py_exr = str(tmp_path / "py.exr")
    sk.write_geometry_image_exr(py_exr, image, source_mesh=mesh_path, sphere_map=sphere)
    back, _ = sk.read_geometry_image_exr(py_exr)
    assert np.array_equal(back.positions, image.positions)

    remesh = sk.geometry_image_mesh(image)
    assert sk.remesh_psnr(mesh, remesh, samples=20000) > 40
    levels, combined = sk.write_gltf_lods(str(tmp_path / "a"), mesh, result.S, image, levels=3, name="a")
    assert len(levels) == 3 and all(os.path.getsize(p) > 0 for p in levels + [combined])
    points, rms = sk.write_cage(str(tmp_path / "a_cage.obj"), mesh, result.S, n=2)
    assert points.shape == (6 * 2 * 2 + 2, 3) and rms >= 0
    assert (tmp_path / "a_cage.obj").read_text().count("\nf ") == 6 * 2 * 2


def test_check_and_correspond(samples):
    a = sk.read_mesh(str(samples / "sample_a.obj"))
    report = sk.check(a)
    assert report["accepted"] and report["genus"] == 0 and report["vertices"] == a.vertices
    torus = sk.check(sk.read_mesh(str(ROOT / "tests" / "data" / "bad" / "genus1_torus.obj")))
    assert not torus["accepted"] and torus["genus"] == 1 and torus["problem"]
    # A point sent from a mesh to itself through its own map comes back where it was.
    r = sk.param(a, effort=0)
    pts = a.V[:5] * 0.999 + a.V[5:10] * 0.001
    positions, faces, in_hole = sk.correspond(a, r.S, a, r.S, pts)
    assert positions.shape == (5, 3) and (faces >= 0).all()
    assert np.abs(positions - pts).max() < 1e-2 * report["bbox_diag"]
