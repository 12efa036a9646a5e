"""
Common names of the database's books
====================================

The refractiveindex.info database names a book by its formula (``Au``,
``Cu-Zn``, ``TiN``); an artist looks for "gold", "brass", "titanium
nitride". This table gives each book of the conductor catalogue its common
name, its category and the other names people search for. It is keyed by
book, never by page: the catalogue (:mod:`fitting.batch.catalogue`) takes
the pages from the shelf, and a book the table lacks stops the build, so
the table follows the shelf.

-   :data:`BOOK_NAMES`: book -> :class:`BookName`.
-   :data:`CATEGORIES`: the categories, in the order the library shows them.
-   :func:`page_name`: the common name of one page (an alloy's page names
    its composition: ``Cu-Zn/Querry-Cu70Zn30`` is "brass 70/30").
"""

from __future__ import annotations

import re
from typing import NamedTuple

__all__ = ["BookName", "BOOK_NAMES", "CATEGORIES", "page_name"]

CATEGORIES: tuple[str, ...] = (
    "metal",
    "alloy",
    "intermetallic",
    "nitride",
    "carbide",
    "hydride",
    "oxide",
    "semimetal",
    "semiconductor",
    "layered crystal",
    "carbon",
    "perovskite",
    "organic",
)


class BookName(NamedTuple):
    """A book's common name, its formula as shown, its category and other names searched for."""

    name: str
    symbol: str
    category: str
    aliases: tuple[str, ...] = ()
    page_pattern: str | None = None
    """A regular expression on the page name whose groups fill :attr:`page_template`."""
    page_template: str | None = None


def _m(name, symbol, *aliases):
    return BookName(name, symbol, "metal", aliases)


BOOK_NAMES: dict[str, BookName] = {
    # Elements that conduct.
    "Ag": _m("silver", "Ag"),
    "Al": _m("aluminium", "Al", "aluminum"),
    "Au": _m("gold", "Au"),
    "Be": _m("beryllium", "Be"),
    "Ca": _m("calcium", "Ca"),
    "Co": _m("cobalt", "Co"),
    "Cr": _m("chromium", "Cr", "chrome"),
    "Cs": _m("caesium", "Cs", "cesium"),
    "Cu": _m("copper", "Cu"),
    "Fe": _m("iron", "Fe"),
    "Hg": _m("mercury", "Hg", "quicksilver"),
    "In": _m("indium", "In"),
    "Ir": _m("iridium", "Ir"),
    "K": _m("potassium", "K"),
    "Li": _m("lithium", "Li"),
    "Mg": _m("magnesium", "Mg"),
    "Mn": _m("manganese", "Mn"),
    "Mo": _m("molybdenum", "Mo"),
    "Na": _m("sodium", "Na"),
    "Nb": _m("niobium", "Nb"),
    "Ni": _m("nickel", "Ni"),
    "Os": _m("osmium", "Os"),
    "Pb": _m("lead", "Pb"),
    "Pd": _m("palladium", "Pd"),
    "Pt": _m("platinum", "Pt"),
    "Rb": _m("rubidium", "Rb"),
    "Rh": _m("rhodium", "Rh"),
    "Ta": _m("tantalum", "Ta"),
    "Ti": _m("titanium", "Ti"),
    "V": _m("vanadium", "V"),
    "W": _m("tungsten", "W", "wolfram"),
    "Zn": _m("zinc", "Zn"),
    "Zr": _m("zirconium", "Zr"),
    "Bi": BookName("bismuth", "Bi", "semimetal"),
    "Te": BookName("tellurium", "Te", "semimetal"),
    # Alloys: the page names the composition.
    "Cu-Zn": BookName("brass", "Cu-Zn", "alloy", ("brass",), r"Cu(\d+)Zn(\d+)", "brass {0}/{1}"),
    "Au-Ag": BookName(
        "gold-silver alloy",
        "Au-Ag",
        "alloy",
        ("electrum", "white gold"),
        r"Au(\d+)Ag(\d+)",
        "gold-silver alloy Au{0} Ag{1}",
    ),
    "Ni-Fe": BookName("nickel-iron alloy", "Ni-Fe", "alloy", ("permalloy",)),
    "stainless_steel": BookName(
        "stainless steel", "Fe-Cr", "alloy", ("steel", "inox"), r"(austenitic|ferritic)", "stainless steel, {0}"
    ),
    "AuAl2": BookName("gold aluminide", "AuAl2", "intermetallic", ("purple gold",)),
    "PtAl2": BookName("platinum aluminide", "PtAl2", "intermetallic"),
    # Nitrides, carbides, hydrides.
    "TiN": BookName("titanium nitride", "TiN", "nitride"),
    "GaN": BookName("gallium nitride", "GaN", "nitride"),
    "B4C": BookName("boron carbide", "B4C", "carbide"),
    "SiC": BookName("silicon carbide", "SiC", "carbide"),
    "Ti3C2": BookName("titanium carbide MXene", "Ti3C2", "carbide", ("mxene",)),
    "TiH2": BookName("titanium hydride", "TiH2", "hydride"),
    "MgH2": BookName("magnesium hydride", "MgH2", "hydride"),
    "Pd-H": BookName("palladium hydride", "Pd-H", "hydride"),
    "V-H": BookName("vanadium hydride", "V-H", "hydride"),
    "Zr-H": BookName("zirconium hydride", "Zr-H", "hydride"),
    # Oxides that absorb.
    "Al2O3": BookName("oxidised aluminium mirror", "Al2O3", "oxide", ("aluminium oxide", "alumina")),
    "Fe2O3": BookName("hematite", "Fe2O3", "oxide", ("iron oxide",)),
    "VO2": BookName("vanadium dioxide", "VO2", "oxide"),
    "BaTiO3": BookName("barium titanate", "BaTiO3", "oxide"),
    "ZnO-CdO": BookName("zinc cadmium oxide", "ZnO-CdO", "oxide"),
    # Semiconductors.
    "Si": BookName("silicon", "Si", "semiconductor"),
    "Ge": BookName("germanium", "Ge", "semiconductor"),
    "Si-Ge": BookName("silicon-germanium", "Si-Ge", "semiconductor"),
    "GaAs": BookName("gallium arsenide", "GaAs", "semiconductor"),
    "GaSb": BookName("gallium antimonide", "GaSb", "semiconductor"),
    "InAs": BookName("indium arsenide", "InAs", "semiconductor"),
    "InP": BookName("indium phosphide", "InP", "semiconductor"),
    "InSb": BookName("indium antimonide", "InSb", "semiconductor"),
    "AlSb": BookName("aluminium antimonide", "AlSb", "semiconductor"),
    "AlAs-GaAs": BookName("aluminium gallium arsenide", "AlGaAs", "semiconductor"),
    "AlSb-GaSb": BookName("aluminium gallium antimonide", "AlGaSb", "semiconductor"),
    "GaAs-InAs": BookName("indium gallium arsenide", "InGaAs", "semiconductor"),
    "GaAs-InAs-GaP-InP": BookName("indium gallium arsenide phosphide", "InGaAsP", "semiconductor"),
    "CdS": BookName("cadmium sulfide", "CdS", "semiconductor"),
    "CdSe": BookName("cadmium selenide", "CdSe", "semiconductor"),
    "CdTe": BookName("cadmium telluride", "CdTe", "semiconductor"),
    "PbSe": BookName("lead selenide", "PbSe", "semiconductor"),
    "As2Se3": BookName("arsenic selenide", "As2Se3", "semiconductor"),
    "Ge2Sb2Te5": BookName("germanium antimony telluride", "Ge2Sb2Te5", "semiconductor", ("gst",)),
    "SnSe": BookName("tin selenide", "SnSe", "semiconductor"),
    # Layered crystals (transition-metal dichalcogenides and kin).
    "Bi2Se3": BookName("bismuth selenide", "Bi2Se3", "layered crystal"),
    "In2Se3": BookName("indium selenide", "In2Se3", "layered crystal"),
    "MoOCl2": BookName("molybdenum oxide dichloride", "MoOCl2", "layered crystal"),
    "MoS2": BookName("molybdenum disulfide", "MoS2", "layered crystal", ("molybdenite",)),
    "MoSe2": BookName("molybdenum diselenide", "MoSe2", "layered crystal"),
    "MoTe2": BookName("molybdenum ditelluride", "MoTe2", "layered crystal"),
    "NbSe2": BookName("niobium diselenide", "NbSe2", "layered crystal"),
    "NiPS3": BookName("nickel phosphorus trisulfide", "NiPS3", "layered crystal"),
    "PdSe2": BookName("palladium diselenide", "PdSe2", "layered crystal"),
    "PtS2": BookName("platinum disulfide", "PtS2", "layered crystal"),
    "PtSe2": BookName("platinum diselenide", "PtSe2", "layered crystal"),
    "ReS2": BookName("rhenium disulfide", "ReS2", "layered crystal"),
    "SnSe2": BookName("tin diselenide", "SnSe2", "layered crystal"),
    "TaS2": BookName("tantalum disulfide", "TaS2", "layered crystal"),
    "TaSe2": BookName("tantalum diselenide", "TaSe2", "layered crystal"),
    "WS2": BookName("tungsten disulfide", "WS2", "layered crystal"),
    "WSe2": BookName("tungsten diselenide", "WSe2", "layered crystal"),
    "WTe2": BookName("tungsten ditelluride", "WTe2", "layered crystal"),
    "ZrSe2": BookName("zirconium diselenide", "ZrSe2", "layered crystal"),
    "ZrTe5": BookName("zirconium pentatelluride", "ZrTe5", "layered crystal"),
    # Carbon.
    "C": BookName("carbon", "C", "carbon", ("graphite", "graphene")),
    "HAC": BookName("hydrogenated amorphous carbon", "a-C:H", "carbon"),
    "diesel_soot": BookName("diesel soot", "C", "carbon", ("soot",)),
    # Perovskites and organic conductors.
    "2D_HOIP": BookName("layered hybrid perovskite", "2D HOIP", "perovskite"),
    "CH3NH3PbI3": BookName("methylammonium lead iodide", "MAPbI3", "perovskite"),
    "C6H4S4-C12H4N4": BookName("TTF-TCNQ", "TTF-TCNQ", "organic"),
    "Cu-C12H4N4": BookName("copper TCNQ", "Cu-TCNQ", "organic"),
    "Li-C12H4N4": BookName("lithium TCNQ", "Li-TCNQ", "organic"),
    "PTB7-PC71BM": BookName("PTB7:PC71BM blend", "PTB7:PC71BM", "organic"),
}
"""Each book of the catalogue: common name, formula, category, other names (see the module docstring)."""


def page_name(book: str, page: str) -> str:
    """
    The common name of ``book``'s ``page``: the book's name, or for a book
    with a page pattern (an alloy's composition) the name it fills in.

    Raises
    ------
    ValueError
        If ``book`` has no entry in :data:`BOOK_NAMES`.
    """
    if book not in BOOK_NAMES:
        raise ValueError(f"`book` {book!r} has no common name in fitting.optics.names.BOOK_NAMES")
    entry = BOOK_NAMES[book]
    if entry.page_pattern is not None and entry.page_template is not None:
        found = re.search(entry.page_pattern, page)
        if found:
            return entry.page_template.format(*found.groups())
    return entry.name
