"""``python -m fitting scene FILE [-o PACK] [--json]`` (fitting.cli.scene.scene_command)."""

import argparse
import json

import pytest
from conftest import run_command

from fitting.cli.scene import add_scene_parser
from fitting.models.pack import decode_pack, pack_from_json

SCENE = {
    "name": "desk",
    "materials": [
        {"material": "Cu", "eta_i": 1.5},
        {"material": "Au", "name": "uncoated gold", "eta_i": 1},
    ],
}


def run_scene(argv):
    parser = argparse.ArgumentParser()
    add_scene_parser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["scene", *argv])
    return args.func(args)


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "desk.json"
    path.write_text(json.dumps(SCENE))
    return path


class TestSceneCommand:
    def test_table_and_binary_pack(self, scene_file, tmp_path, capsys):
        out = tmp_path / "desk.cfpk"
        assert run_scene([str(scene_file), "-o", str(out)]) == 0
        table = capsys.readouterr().out
        assert "scene desk" in table and "uncoated gold" in table
        assert "pack " in table and "(general " in table
        pack = decode_pack(out.read_bytes())
        assert [m.name for m in pack] == ["Cu", "uncoated gold"]
        assert all(m.degree == 0 for m in pack)
        assert pack[1].eta_i_range == (1.0, 1.0)

    def test_json_report_and_json_pack(self, scene_file, tmp_path, capsys):
        out = tmp_path / "desk.json.pack.json"
        assert run_scene([str(scene_file), "--json", "--output", str(out)]) == 0
        report = json.loads(capsys.readouterr().out)
        assert report["output"] == str(out)
        assert report["totals"]["pack_bytes"] < report["totals"]["general_pack_bytes"]
        pack = pack_from_json(out.read_text())
        assert [m.name for m in pack] == [m["name"] for m in report["materials"]]

    def test_existing_output_is_never_overwritten(self, scene_file, tmp_path, capsys):
        out = tmp_path / "saved.cfpk"
        out.write_bytes(b"the user's own pack")
        assert run_scene([str(scene_file), "-o", str(out)]) == 2
        err = capsys.readouterr().err
        assert "`--output`" in err and "never overwritten" in err
        assert out.read_bytes() == b"the user's own pack"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["desk.json", "saved.cfpk"]

    def test_bad_scene_is_refused_with_the_field(self, tmp_path, capsys):
        path = tmp_path / "bad.json"
        path.write_text(json.dumps({"materials": [{"material": "Au", "eta_i": 0.5}]}))
        assert run_scene([str(path)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: ") and r"`materials[0].eta_i` must lie in [1, 3]" in err

    def test_missing_file(self, tmp_path, capsys):
        assert run_scene([str(tmp_path / "nope.json")]) == 2
        assert "cannot read scene `FILE`" in capsys.readouterr().err

    def test_unwritable_output_leaves_nothing(self, scene_file, tmp_path, capsys):
        out = tmp_path / "no-such-dir" / "p.cfpk"
        assert run_scene([str(scene_file), "-o", str(out)]) == 2
        assert "cannot write `--output`" in capsys.readouterr().err
        assert not out.parent.exists()


@pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
def test_python_m_fitting_scene(scene_file, tmp_path):
    out = tmp_path / "desk.cfpk"
    done = run_command("fitting", "scene", str(scene_file), "-o", str(out), "--json", timeout=120)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert len(decode_pack(out.read_bytes())) == len(report["materials"]) == 2
