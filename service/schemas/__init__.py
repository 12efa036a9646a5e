"""
Request and response models
===========================

Every pydantic model of the HTTP API, in one package, one module per
resource. Constraints live on the fields (built from the core's constants),
so bad input is refused by the schema and shows in the OpenAPI document.

-   :mod:`.common`: constants, field types, :class:`ErrorBody`, :class:`Mirror`.
-   :mod:`.metrics`: the mirror of the core's error metrics.
-   :mod:`.fits`: n, k fits, packs, plotted curves; :func:`fit_public`.
-   :mod:`.curves`: curve fits and error maps.
-   :mod:`.colours`: the curves of a metal given by a base colour and an edge tint.
-   :mod:`.scenes`: scene packs.
-   :mod:`.materials`: the material list and details, versions, edits.
-   :mod:`.library`: the library to browse, coat presets.
-   :mod:`.health`: health and the domain.
"""

from .common import *  # noqa: F401,F403
from .common import __all__ as _common
from .colours import *  # noqa: F401,F403
from .colours import __all__ as _colours
from .curves import *  # noqa: F401,F403
from .curves import __all__ as _curves
from .fits import *  # noqa: F401,F403
from .fits import __all__ as _fits
from .health import *  # noqa: F401,F403
from .health import __all__ as _health
from .library import *  # noqa: F401,F403
from .library import __all__ as _library
from .materials import *  # noqa: F401,F403
from .materials import __all__ as _materials
from .metrics import *  # noqa: F401,F403
from .metrics import __all__ as _metrics
from .scenes import *  # noqa: F401,F403
from .scenes import __all__ as _scenes

__all__ = [*_common, *_colours, *_metrics, *_fits, *_curves, *_scenes, *_materials, *_library, *_health]
