"""
A toy export format, added as this one file: USD's text form (``.usda``)
with a ``UsdPreviewSurface`` whose specular colour is the metal's Schlick
F0 under the coat. It registers itself when imported; a test loads it into
the CLI and the service with ``COATED_PLUGINS=tests/toy_export_format.py``
(tests/static/test_toy_export_format.py).
"""

from __future__ import annotations

import json
import re

from fitting.exports import ExportFormat, ExportValues, register_export_format


def usda_document(values: ExportValues) -> str:
    r, g, b = (float(c) for c in values.F0_schlick)
    prim = re.sub(r"\W", "_", values.name) or "material"
    doc = json.dumps(f"{values.name}: {values.source}; coat eta_i {values.eta_i:g}")
    return f"""#usda 1.0
(
    doc = {doc}
)

def Material "{prim}"
{{
    token outputs:surface.connect = </{prim}/Surface.outputs:surface>

    def Shader "Surface"
    {{
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:specularColor = ({r:.6f}, {g:.6f}, {b:.6f})
        float inputs:metallic = 1
        float inputs:roughness = {values.roughness:g}
        float inputs:clearcoat = {0.0 if values.eta_i == 1.0 else 1.0:g}
        float inputs:clearcoatRoughness = {values.coat_roughness:g}
        token outputs:surface
    }}
}}
"""


register_export_format(
    ExportFormat(
        name="usda",
        label="USD preview surface (.usda)",
        media_type="model/vnd.usda",
        extension="usda",
        tools=(),
        write=usda_document,
    )
)
