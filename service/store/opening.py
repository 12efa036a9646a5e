"""
Opening the configured store
============================

:func:`open_store`: the store the settings name, PostgreSQL when
``COATED_STORE_URL`` is set, else SQLite under the data directory; the
one place that chooses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .records import Store
from .sqlite import SQLiteStore

if TYPE_CHECKING:
    from ..config import Settings

__all__ = ["open_store"]


def open_store(settings: "Settings", migrate: bool | None = None) -> Store:
    """
    The store of ``settings``, its schema migrated when ``migrate`` (default
    ``settings.store_migrate``). Raises :class:`service.store.StoreError`.
    """
    migrate = settings.store_migrate if migrate is None else migrate
    if settings.store_url is not None:
        from .postgres import PostgresStore  # psycopg is loaded only for a PostgreSQL store

        return PostgresStore(
            settings.store_url.get_secret_value(),
            pool_min=settings.store_pool_min,
            pool_max=settings.store_pool_max,
            pool_timeout_s=settings.store_pool_timeout_s,
            statement_timeout_s=settings.store_statement_timeout_s,
            max_bytes=settings.store_max_bytes,
            migrate=migrate,
        )
    return SQLiteStore(settings.store_path, settings.store_max_bytes, settings.store_min_free_bytes, migrate=migrate)
