"""Fur in the sandbox: strands as ribbons and control markers (`strands`, `ribbons`,
`markers`), the fur panel and its timeline (`furpanel`, `timeline`).

Imported only by the fur plugin's sandbox entries (they need pyglet and a GL context).
"""
