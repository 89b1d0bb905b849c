"""The browser trainer: a local Starlette server with one WebSocket per trainee session.

Layer: edge (between ``cli`` and ``progress``). Needs the optional extra
``stereoplotter[trainer]``.
"""
