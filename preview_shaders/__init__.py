"""
preview_shaders: the coated-conductor model as a renderer runs it
=================================================================

GLSL mirrors of :mod:`fitting.models.coated_conductor` and its baselines (``glsl/``), the
headless GL machinery that runs them on one dedicated render thread, and the
preview sphere the service and the editor show.

-   :mod:`preview_shaders.gl`: the GL context and its render thread.
-   :mod:`preview_shaders.evaluate`: full-screen evaluation of each shader
    variant (parity tests, cost benchmark).
-   :mod:`preview_shaders.preview`: :class:`PreviewRenderer`, the preview
    sphere (service entry point ``render_preview``).
-   :mod:`preview_shaders.display`: the ACEScg to sRGB display transform.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from .evaluate import VARIANTS, ShaderInputs, evaluate_grid, shader_inputs, time_variants
from .gl import RenderThread, load_shader_source
from .preview import PreviewRenderer, PreviewResult

__all__ = [
    "VARIANTS",
    "ShaderInputs",
    "evaluate_grid",
    "shader_inputs",
    "time_variants",
    "RenderThread",
    "load_shader_source",
    "PreviewRenderer",
    "PreviewResult",
]
