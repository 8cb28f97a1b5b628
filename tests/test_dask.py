"""The same units on a Dask cluster: a distributed.LocalCluster with 2 worker processes runs the dense-matching
pairs, the depth fusion and the orthophoto tiles, and the products are identical to the local run's."""
import os
import shutil

import numpy as np
import pytest

from core.common import parallel
from core.dense import stage as dense
from core.dense.options import DenseOptions
from core.io import raster as dsm
from core.ortho.options import OrthoOptions
from core.ortho.stage import build_orthophoto_workspace
from tests import synthetic as syn
from tests.test_dense import CAMERA, make_workspace

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def cluster():
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=40) as c:
        yield c


@pytest.fixture(scope="module")
def block_root(tmp_path_factory):
    root = tmp_path_factory.mktemp("dask block")
    block = syn.vertical_block(seed=8, camera=CAMERA, altitude=40.0, n_strips=2, per_strip=4, forward_overlap=0.8,
                               side_overlap=0.5, gcp_grid=(2, 2), roofs=0)
    block.render(str(root / "images"))
    return block, str(root)


def _workspace(block_root, name):
    block, root = block_root
    return make_workspace(os.path.join(root, name), block, images_dir=os.path.join(root, "images"))


def _raster(path):
    from osgeo import gdal

    ds = gdal.Open(path)
    return ds.ReadAsArray(), ds.GetGeoTransform(), ds.GetProjection()


def test_dask_products_are_identical_to_the_local_run(block_root, cluster):
    local = _workspace(block_root, "local")
    remote = _workspace(block_root, "dask")
    r_local = dense.build_dsm_workspace(local, DenseOptions(quality="full", workers=1))
    r_dask = dense.build_dsm_workspace(remote, DenseOptions(quality="full", scheduler=cluster.scheduler_address))
    assert r_local.pairs == r_dask.pairs >= 4
    assert any("Dask" in line for line in r_dask.log_lines), r_dask.log_lines
    z_l, gt_l, _ = dsm.read_dsm(r_local.dsm_path)
    z_d, gt_d, _ = dsm.read_dsm(r_dask.dsm_path)
    assert gt_l == gt_d
    assert np.isfinite(z_l).mean() > 0.5
    np.testing.assert_array_equal(z_l, z_d)

    o_local = build_orthophoto_workspace(local, OrthoOptions(workers=1, tile=128))
    o_dask = build_orthophoto_workspace(remote, OrthoOptions(tile=128, scheduler=cluster.scheduler_address))
    a_l, g_l, p_l = _raster(o_local.orthomosaic)
    a_d, g_d, p_d = _raster(o_dask.orthomosaic)
    assert g_l == g_d and p_l == p_d
    assert (a_l[-1] > 0).mean() > 0.5  # alpha: the mosaic has content
    np.testing.assert_array_equal(a_l, a_d)


def test_scheduler_from_the_environment(monkeypatch, cluster):
    monkeypatch.setenv(parallel.SCHEDULER_ENV, cluster.scheduler_address)
    with parallel.make_executor(workers=1) as ex:
        assert parallel.describe_executor(ex) == f"Dask cluster {cluster.scheduler_address}: 2 worker thread(s)"
        assert ex.submit(pow, 3, 4).result() == 81
    monkeypatch.setenv(parallel.SCHEDULER_ENV, "")
    with parallel.make_executor(workers=1) as ex:
        assert isinstance(ex, parallel.SerialExecutor)


def test_unreachable_scheduler_is_a_clear_error():
    with pytest.raises(parallel.ParallelError, match="tcp://127.0.0.1:9"):
        parallel.make_executor(scheduler="tcp://127.0.0.1:9", connect_timeout=2)


def test_workers_see_the_shared_path(block_root, cluster, tmp_path):
    """Units read their inputs from and write their outputs to paths every worker sees."""
    src = os.path.join(block_root[1], "images")
    names = sorted(os.listdir(src))[:2]
    units = [(os.path.join(src, n), str(tmp_path / f"{n}.npy")) for n in names]
    with parallel.make_executor(scheduler=cluster.scheduler_address) as ex:
        results = dict(parallel.run_units(ex, _copy_unit, units))
    assert sorted(results) == [0, 1]
    for (path, out), (_, size) in zip(units, sorted(results.items())):
        assert os.path.getsize(out) == size > 0
    shutil.rmtree(tmp_path, ignore_errors=True)


def _copy_unit(unit, cancel_path=None):
    src, dst = unit
    shutil.copyfile(src, dst)
    return os.path.getsize(dst)
