"""The designer's bench: ``pneumorph serve``, a local web page over the certified search.

A target typed or drawn on the page gets the chain model's certified answer at once
(:class:`Bench`); an FE verification, an export or a chain table runs in the background
(:class:`JobBoard`). The web stack (FastAPI, uvicorn) is the ``web`` extra:
``pip install -e ".[web]"``.
"""

from pneumorph.bench.answer import Bench, profiles
from pneumorph.bench.jobs import Job, JobBoard
from pneumorph.bench.query import Query, QueryError, parse_query
from pneumorph.bench.shapes import chain_placement, surface


def create_app(*args, **kwargs):
    """The bench's ASGI application (:func:`pneumorph.bench.app.create_app`; needs the ``web`` extra)."""
    from pneumorph.bench.app import create_app as make

    return make(*args, **kwargs)


__all__ = ["Bench", "Job", "JobBoard", "Query", "QueryError", "chain_placement", "create_app", "parse_query",
           "profiles", "surface"]
