# The folder-level jobs (make_collection, add_to_collection, convert, convert_collection) against
# the command line: the same files byte for byte, for any thread count; the same error messages;
# cancellation leaves no output.
import filecmp
import json
import os
import shutil
import subprocess

import pytest

import spherekit as sk
from conftest import cli_error


def same_tree(a, b):
    """Every file of folder a is in b with the same bytes, and b has no others."""
    names_a = sorted(os.listdir(a))
    assert names_a == sorted(os.listdir(b))
    match, mismatch, errors = filecmp.cmpfiles(a, b, names_a, shallow=False)
    assert not mismatch and not errors, f"differ: {mismatch} {errors}"


@pytest.fixture(scope="module")
def collection(exe, samples, tmp_path_factory):
    """A 2-member collection written by the command line, and the third sample to add."""
    col = tmp_path_factory.mktemp("cli") / "col"
    subprocess.run([exe, "consistent", "-o", str(col), str(samples / "sample_a.obj"), str(samples / "sample_b.obj"),
                    "--remesh-size", "33", "--effort", "1", "--quiet"], check=True)
    return col


def test_make_collection_writes_the_cli_folder(collection, samples, tmp_path):
    out = tmp_path / "col"
    manifest = sk.make_collection([str(samples / "sample_a.obj"), str(samples / "sample_b.obj")], str(out),
                                  remesh_size=33, effort=1, threads=1)
    assert [m["name"] for m in manifest["meshes"]] == ["sample_a", "sample_b"]
    assert manifest["output"] == str(out)
    assert manifest["landmark_warnings"] == []  # the samples' files correspond
    same_tree(collection, out)  # the CLI ran with all cores: the bytes do not depend on it


def test_add_to_collection_writes_what_add_writes(exe, collection, samples, tmp_path):
    cli_col, py_col = tmp_path / "cli", tmp_path / "py"
    shutil.copytree(collection, cli_col)
    shutil.copytree(collection, py_col)
    subprocess.run([exe, "add", str(cli_col), str(samples / "sample_c.obj"), "--quiet"], check=True)
    r = sk.add_to_collection(str(py_col), str(samples / "sample_c.obj"), threads=2)
    assert r["name"] == "sample_c" and not r["registered"]
    assert r["result"]["flipped_faces"] == 0
    assert r["landmark_warnings"] == []
    assert "sample_c" in [m["name"] for m in r["manifest"]["meshes"]]
    same_tree(cli_col, py_col)

    # Adding it again without replace is refused with the command line's message.
    code, message = cli_error(exe, "add", str(cli_col), str(samples / "sample_c.obj"), "--quiet")
    with pytest.raises(sk.Error) as e:
        sk.add_to_collection(str(py_col), str(samples / "sample_c.obj"))
    assert str(e.value) == message


def test_convert_writes_the_cli_files_for_any_thread_count(exe, samples, collection, tmp_path):
    mesh = str(samples / "sample_a.obj")
    sphere = str(collection / "sample_a.sphere.obj")
    # Both write into the same folder name (the files record their siblings' paths), renamed after.
    out = tmp_path / "out"
    out.mkdir()
    subprocess.run([exe, "convert", mesh, sphere, "-o", str(out / "a.exr"), "--size", "65", "--lods", "2",
                    "--cage", "4", "--cage-tile", "5", "--psnr-samples", "2000", "--threads", "2", "--quiet"],
                   check=True)
    cli_dir, py_dir = tmp_path / "cli", tmp_path / "py"
    out.rename(cli_dir)
    out.mkdir()
    report = sk.convert(mesh, sphere, str(out / "a.exr"), size=65, lods=2, cage=4, cage_tile=5, psnr_samples=2000,
                        threads=1)
    out.rename(py_dir)
    same_tree(cli_dir, py_dir)
    assert report["size"] == 65 and len(report["lods"]) == 2
    assert report["psnr_db"] > 20 and report["cage"]["quads"] == 6 * 4 * 4


def test_convert_collection_and_its_errors(exe, collection, tmp_path):
    report = sk.convert_collection(str(collection), str(tmp_path / "assets"), size=33, lods=1, psnr_samples=0)
    assert [m["name"] for m in report["members"]] == ["sample_a", "sample_b"]
    on_disk = json.loads((tmp_path / "assets" / "convert_report.json").read_text())
    assert on_disk["members"][0]["image"] == report["members"][0]["image"]

    code, message = cli_error(exe, "convert", "--collection", str(collection), "-o", str(tmp_path / "x"), "--size", "100")
    with pytest.raises(sk.InvalidArgument) as e:
        sk.convert_collection(str(collection), str(tmp_path / "x"), size=100)
    assert str(e.value) == message
    with pytest.raises(sk.InvalidArgument):
        sk.convert_collection(str(collection), str(tmp_path / "x"), lod_mode="fancy")
    assert not (tmp_path / "x").exists()


def test_cancelled_convert_leaves_no_folder(collection, tmp_path):
    out = tmp_path / "assets"
    with pytest.raises(sk.Cancelled):
        sk.convert_collection(str(collection), str(out), size=33, lods=2, cage=2, cage_tile=3, psnr_samples=0,
                              progress=lambda stage, level, fraction: False)
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir()], "a cancelled job left files behind"
