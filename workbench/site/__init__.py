"""A static site of the results store (``workbench results report --html DIR``), opened from
disk without a server: no network, no CDN, every link relative.

The index lists every experiment with a stored quick or full run and its claims (each ratio
with its interval), the run they come from, its machine, commit and size; each experiment's
page holds its tables (sortable, with their column legends), a Pareto plot of time against
error per table that has both, and its figures inline, each linked to the run that made it;
a page per machine gives its fingerprint; a history page per experiment shows each claim's
columns over the stored runs with change points marked.

Modules:

* :mod:`~workbench.site.contents`: what the site shows, gathered from the store (few queries);
* :mod:`~workbench.site.figures`: an experiment's figure files and the run that made each
  (``provenance.json``);
* :mod:`~workbench.site.plots`: the Pareto and history plots (matplotlib, PNG);
* :mod:`~workbench.site.markup`: the HTML pieces (page shell, tables, legends, links);
* :mod:`~workbench.site.pages`: the index, experiment, runs and machine pages;
* :mod:`~workbench.site.history`: the history pages (from :mod:`workbench.results.history`);
* :mod:`~workbench.site.assets`: the style sheet and the table sorter;
* :mod:`~workbench.site.writing`: :func:`write_site`, the whole site written at once.
"""

from .writing import write_site

__all__ = ["write_site"]
