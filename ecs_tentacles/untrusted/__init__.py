"""Reading what comes from elsewhere, or what the project wrote earlier: never trusted.

A scene folder, a take, a level, the mesh cache, work shards, best times: each may
have been written by someone else, cut short by a killed process or replaced by a
FIFO. What reads them goes through here:

- `files`: only a regular file is opened (without blocking: a FIFO is refused, never
  waited on; links not followed where asked) and never more than a stated size read;
- `bounded_json`: JSON within a size, a depth and a number length, its errors one line
  naming the JSON path (take and shard headers);
- `strict_json`: JSON as users write it, every key once in its object and every number
  finite (scenes and levels).

What each reader checks beyond that (digests, signatures, budgets) is in the
handbook's "Files it trusts and checks" (docs/trust.md).
"""
