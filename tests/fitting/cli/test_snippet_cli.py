"""``python -m fitting fit --snippet glsl|hlsl``: the service's shader downloads, written by the CLI."""

from __future__ import annotations

import pytest

from fitting.cli.main import main


@pytest.mark.parametrize(
    "language, words",
    [
        ("glsl", ("vec3 cf_material_Al(float NdotV, float eta_i)", "mat3")),
        ("hlsl", ("float3 cf_material_Al(float NdotV, float eta_i)", "float3x3")),
    ],
)
def test_fit_writes_a_snippet(tmp_path, capsys, language, words):
    out = tmp_path / f"al.{language}"
    assert main(["fit", "Al", "--snippet", language, "--no-metrics", "-o", str(out)]) == 0
    text = out.read_text()
    assert all(word in text for word in words), text[:400]
    assert "Delta E 2000: not measured" in text  # the header says the fit's figure (here: none taken)
    assert "wrote" in capsys.readouterr().err


def test_an_unknown_language_is_refused(capsys):
    with pytest.raises(SystemExit):
        main(["fit", "Al", "--snippet", "wgsl"])
    assert "invalid choice: 'wgsl'" in capsys.readouterr().err
