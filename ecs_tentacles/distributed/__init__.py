"""Distributed bakes on Ray: shards of creatures that never meet, and wedges of variants.

- `shards`: which creatures a bake may simulate apart (declared in the scene, or
  worked out from where each creature can travel during the bake), packed into tasks.
- `task`: one shard's bake, as a Ray worker runs it (only its creatures built).
- `spheres`: the contact-range check that proves shards never met (else they re-bake
  together), so a sharded bake always equals the local one.
- `merge`: shard takes -> the one take a local bake writes, byte for byte.
- `work`: the work folder beside the output; finished shards are kept for `--resume`,
  signed with this user's key (`secret`), and used again only if the signature holds.
- `driver`: starts or joins Ray, runs the tasks with retries and one progress bar.
- `wedge`: `--wedge PATH=VALUES` parameter variations, their outputs and `wedge.json`.

Nothing here imports Ray at module level: a local bake never loads it.
"""
