"""Fur's drawing in the sandbox: ribbons, control markers, the fur panel and timeline.

Imported only by the fur plugin's render hooks (they need pyglet and a GL context).
"""
