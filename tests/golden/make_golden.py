"""
Regenerate the golden previews (run from the repository root):

    .venv/bin/python tests/golden/make_golden.py          # images only
    .venv/bin/python tests/golden/make_golden.py --refit  # also the pack

The pack ``Au_golden.json`` is a fit of the built-in Au frozen here, so the
goldens guard the renderer, not the fitter. Regenerate only after checking
that a change of the pictures is intended (look at them).
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from fitting.models.pack import pack_from_json, pack_to_json
from fitting.optics.library import library_material
from preview_shaders.preview import PreviewRenderer  # noqa: E402

HERE = Path(__file__).resolve().parent
PACK = HERE / "Au_golden.json"
CASES = {
    # name: (eta_i, size, compare, environment)
    "preview_Au_white_sky": (1.5, 96, "none", "white_sky"),
    "preview_Au_lazanyi_2.5": (2.5, 96, "lazanyi", "white_sky"),
    "preview_Au_studio": (1.0, 96, "none", "studio"),
}


def main() -> None:
    nk = library_material("Au")
    if "--refit" in sys.argv or not PACK.exists():
        from fitting.fits.material import fit_material

        PACK.write_text(pack_to_json([fit_material(nk).packed]))
    packed = pack_from_json(PACK.read_text())[0]
    with PreviewRenderer() as renderer:
        for name, (eta_i, size, compare, environment) in CASES.items():
            result = renderer.render_preview(packed, nk, eta_i, size, compare, environment)
            (HERE / f"{name}.png").write_bytes(result.png)
            print(f"wrote {name}.png")


if __name__ == "__main__":
    main()
