"""
Layer 6, command line: ``python -m fitting library | fit | reproduce | scene``.

-   :mod:`.main`: the parser and the ``library`` and ``fit`` commands.
-   :mod:`.reproduce`: ``reproduce``, writes ``docs/results.md``.
-   :mod:`.scene`: ``scene``, fits a scene description.

May import every layer below; nothing imports it but ``fitting.__main__``.
"""
