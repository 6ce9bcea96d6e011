"""Output service of the studies: the one table/figure writer, markdown, figures, publishing (no kind imports)."""

__all__: list[str] = []
