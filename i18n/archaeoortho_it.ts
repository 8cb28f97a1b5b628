<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1">
<context>
    <name>@default</name>
    <message>
        <location filename="../ui/workspace_menu.py" line="61"/>
        <source>ArchaeoOrtho</source>
        <translation>ArchaeoOrtho</translation>
    </message>
    <message>
        <location filename="../ui/workspace_menu.py" line="61"/>
        <source>No web browser opened {}</source>
        <translation>Nessun browser web aperto {}</translation>
    </message>
    <message>
        <location filename="../ui/workspace_menu.py" line="107"/>
        <source>Open accuracy report</source>
        <translation>Apri il rapporto di accuratezza</translation>
    </message>
    <message>
        <location filename="../ui/workspace_menu.py" line="111"/>
        <source>Open accuracy report (none yet: run Accuracy report or Run pipeline)</source>
        <translation>Apri il rapporto di accuratezza (ancora nessuno: esegui Rapporto di accuratezza o Esegui l'intera elaborazione)</translation>
    </message>
</context>
<context>
    <name>AccuracyReportAlgorithm</name>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="72"/>
        <source>Workspace folder</source>
        <translation>Cartella dell'area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="80"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="81"/>
        <source>Camera precision (GeoPackage)</source>
        <translation>Precisione delle camere (GeoPackage)</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="82"/>
        <source>Tie point precision (GeoPackage)</source>
        <translation>Precisione dei punti di legame (GeoPackage)</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="83"/>
        <source>Sections skipped</source>
        <translation>Sezioni saltate</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="100"/>
        <source>section {} skipped: {}</source>
        <translation>sezione {} saltata: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="102"/>
        <source>report written: {} ({} s)</source>
        <translation>rapporto scritto: {} ({} s)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Accuracy report</source>
        <translation>Rapporto di accuratezza</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="72"/>
        <source>Compute uncertainty</source>
        <translation>Calcola l'incertezza</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="77"/>
        <source>Report</source>
        <translation>Rapporto</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Writes one self-contained HTML report of a workspace (plots embedded, readable offline) and returns its key figures.

Sections of the report. Summary — images given / aligned / not aligned and why, image screening, cameras with their calibrated parameters and standard deviations, GSD, area, CRS, processing times and parameters. Orientation quality: reprojection errors, tie-point track lengths, image connectivity, camera positions with residuals. Georeferencing: control and check points with dX dY dZ and image residuals, residual vectors, RMSE per set, NSSDA (FGDC-STD-007.3-1998) accuracy statements at 95 % confidence, ASPRS 2014 and 2023 accuracy classes, camera-position residuals, outliers. Uncertainty: standard deviations of cameras and tie points from the bundle adjustment covariance. Products: DSM and orthomosaic previews, resolution, valid fraction. Sections whose stage has not run are skipped with a note.

Workspace folder: a workspace folder (at least aligned).
Compute uncertainty: computes the bundle adjustment covariance (seconds for hundreds of images) for the uncertainty section and writes &lt;workspace&gt;/uncertainty/cameras.gpkg and points.gpkg.
Report: the report file (default: &lt;workspace&gt;/report.html). It is written under a temporary name and renamed when complete.</source>
        <translation>Scrive un rapporto HTML autonomo di un'area di lavoro (grafici incorporati, leggibile offline) e ne restituisce le cifre principali.

Sezioni del rapporto. Sintesi — immagini fornite / orientate / non orientate e perché, controllo delle immagini, camere con i parametri calibrati e le deviazioni standard, GSD, area, SR, tempi e parametri di elaborazione. Qualità dell'orientamento: errori di riproiezione, lunghezze delle tracce dei punti di legame, connessioni tra immagini, posizioni delle camere con residui. Georeferenziazione: punti d'appoggio e di controllo con dX dY dZ e residui in immagine, vettori dei residui, RMSE per gruppo, accuratezza NSSDA (FGDC-STD-007.3-1998) al 95 % di confidenza, classi di accuratezza ASPRS 2014 e 2023, residui delle posizioni delle camere, valori anomali. Incertezza: deviazioni standard delle camere e dei punti di legame dalla covarianza della compensazione. Prodotti: anteprime di DSM e ortomosaico, risoluzione, frazione valida. Le sezioni la cui fase non è stata eseguita vengono saltate con una nota.

Cartella dell'area di lavoro: una cartella dell'area di lavoro (almeno orientata).
Calcola l'incertezza: calcola la covarianza della compensazione a stelle proiettive (secondi per centinaia di immagini) per la sezione dell'incertezza e scrive &lt;workspace&gt;/uncertainty/cameras.gpkg e points.gpkg.
Rapporto: il file del rapporto (predefinito: &lt;workspace&gt;/report.html). Viene scritto con un nome provvisorio e rinominato quando è completo.</translation>
    </message>
</context>
<context>
    <name>AlgorithmBase</name>
    <message>
        <location filename="../processing_provider/base.py" line="269"/>
        <source>Cancelled: {}</source>
        <translation>Annullato: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/base.py" line="169"/>
        <source>Outputs not styled: {}</source>
        <translation>Output senza stile: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Photogrammetry</source>
        <translation>Fotogrammetria</translation>
    </message>
    <message>
        <location filename="../processing_provider/base.py" line="331"/>
        <source>{}: cancelling (send it again to stop at once)</source>
        <translation>{}: annullamento in corso (invialo di nuovo per fermare subito)</translation>
    </message>
</context>
<context>
    <name>AlignImagesAlgorithm</name>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Folder of images</source>
        <translation>Cartella delle immagini</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Workspace folder</source>
        <translation>Cartella dell'area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Pair selection</source>
        <translation>Selezione delle coppie</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Camera model</source>
        <translation>Modello di camera</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>One camera for all images</source>
        <translation>Una sola camera per tutte le immagini</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="88"/>
        <source>Camera centres</source>
        <translation>Centri di presa</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="89"/>
        <source>Registered images</source>
        <translation>Immagini orientate</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="90"/>
        <source>Mean reprojection error (px)</source>
        <translation>Errore medio di riproiezione (px)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="118"/>
        <source>Registered {} of {} images, mean reprojection error {:.3f} px, {} points</source>
        <translation>Orientate {} di {} immagini, errore medio di riproiezione {:.3f} px, {} punti</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="125"/>
        <source>Images not registered:</source>
        <translation>Immagini non orientate:</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="132"/>
        <source>Seconds per step: {}</source>
        <translation>Secondi per fase: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Align images</source>
        <translation>Allinea immagini</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Mapper</source>
        <translation>Metodo di ricostruzione</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Matching image size (px)</source>
        <translation>Dimensione per la corrispondenza (px)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Features per image</source>
        <translation>Feature per immagine</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Affine-invariant features</source>
        <translation>Feature invarianti affini</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Focal length (mm)</source>
        <translation>Focale (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Sensor width (mm)</source>
        <translation>Larghezza del sensore (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Retry images left out</source>
        <translation>Riprova le immagini escluse</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="121"/>
        <source>Retry {} ({} features): {} image(s) left out; main block {} -&gt; {} images{}</source>
        <translation>Nuovo tentativo {} (caratteristiche {}): {} immagine/i escluse; blocco principale {} -&gt; {} immagini{}</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="121"/>
        <source> (not better: the previous result kept)</source>
        <translation> (non migliore: resta il risultato precedente)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Camera calibration file</source>
        <translation>File di calibrazione della camera</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Interior orientation</source>
        <translation>Orientamento interno</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="130"/>
        <source>Camera {}: interior orientation {} ({})</source>
        <translation>Camera {}: orientamento interno {} ({})</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Camera positions (CSV)</source>
        <translation>Posizioni delle camere (CSV)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Structure from motion: SIFT features, pair selection, robust matching (RANSAC), incremental mapping with self-calibration (focal length, principal point, lens distortion) and a final bundle adjustment. The result is stored in the workspace folder, which the following stages (Georeference, Build DSM, Build orthophoto) take as input. A re-run resumes: features and matches already computed are reused.

Pair selection: &apos;auto&apos; uses EXIF GPS neighbours when the images carry GPS, every pair for up to 100 images otherwise, and sequential pairs with loop pairs for larger sets without GPS. Camera positions (CSV), optional: the photos&apos; positions in the file Georeference takes (a GNSS log, for photos without EXIF GPS) choose the pairs and the probed photos&apos; neighbours instead of EXIF GPS; they do not georeference the block.
Camera model: &apos;AUTO&apos; estimates focal length, principal point, k1, k2, p1, p2 (OPENCV) for cameras with 10 or more images, and a simpler radial model below.
Matching image size: the longest side the images are scaled to for the features (0 = automatic: photos of up to 2 megapixels as they are, larger ones scaled to 2 megapixels; the DSM and the orthophotos use every pixel). Features per image: 0 = automatic (about 4000 per megapixel, 2048 to 4096). With both at 0, a few photos are probed first: where faint, low-contrast texture (ploughed fields) starves them of features, the first pass takes 8192 fainter ones, at up to twice the size if needed (the log says so). Affine-invariant features help with oblique views and are slower.
Focal length and Sensor width: interior orientation when EXIF is missing (scanned film): the focal length and the width of the long side of the frame, in millimetres (0 = from EXIF / unknown).
Camera calibration file: a calibrated camera&apos;s interior orientation (ArchaeoOrtho&apos;s YAML/JSON, Orthority interior parameters, OpenCV, COLMAP cameras.txt or Metashape XML); several cameras are matched to the photos by their image patterns, camera model or image size; a photo of another resolution takes it scaled. A file that cannot be read stops the run before any work, naming the file, the line and the field.
Interior orientation: what the adjustments may change of a camera: &apos;fixed&apos; keeps the given values through the alignment and the georeference (also with automatic control), &apos;refined&apos; lets the georeference refine them with the calibration&apos;s standard deviations as priors, &apos;estimated&apos; self-calibrates from them. &apos;auto&apos; is &apos;fixed&apos; where a calibration is given (the file, or film scans restituted by Prepare images) and &apos;estimated&apos; elsewhere; a camera&apos;s own &apos;adjust&apos; in the file overrides it. With &apos;fixed&apos; or &apos;refined&apos; and no file, the focal length and sensor width are the given values. The log, sfm/alignment.json and the accuracy report say per camera what was held.
Mapper (advanced): &apos;incremental&apos; (COLMAP, the default) or &apos;global&apos; (GLOMAP: rotation averaging and global positioning, often faster on large blocks; a Cancel takes effect only when it has finished).
Retry images left out (advanced, on): images the fast settings leave out, or a block split into parts, are retried with richer features (fainter ones for low-contrast frames, affine-shape ones for steep obliques) and more pairs; the log and sfm/alignment.json say what was retried and why.</source>
        <translation>Structure from motion: feature SIFT, selezione delle coppie, corrispondenza robusta (RANSAC), ricostruzione incrementale con autocalibrazione (focale, punto principale, distorsione dell'obiettivo) e una compensazione a stelle proiettive finale. Il risultato è salvato nella cartella dell'area di lavoro, che le fasi seguenti (Georeferenzia, Genera DSM, Genera ortofoto) prendono come input. Una nuova esecuzione riprende: feature e corrispondenze già calcolate vengono riutilizzate.

Selezione delle coppie: 'auto' usa i vicini secondo il GPS EXIF quando le immagini hanno il GPS, altrimenti ogni coppia fino a 100 immagini, e coppie sequenziali con coppie di chiusura per insiemi più grandi senza GPS. Posizioni delle camere (CSV), facoltativo: le posizioni delle foto nel file che legge Georeferenzia (un registro GNSS, per foto senza GPS EXIF) scelgono le coppie e i vicini delle foto sondate al posto del GPS EXIF; non georeferenziano il blocco.
Modello di camera: 'AUTO' stima focale, punto principale, k1, k2, p1, p2 (OPENCV) per camere con 10 o più immagini e un modello radiale più semplice al di sotto.
Dimensione per la corrispondenza: il lato maggiore a cui le immagini sono ridotte per le feature (0 = automatico: foto fino a 2 megapixel così come sono, quelle più grandi ridotte a 2 megapixel; il DSM e le ortofoto usano ogni pixel). Feature per immagine: 0 = automatico (circa 4000 per megapixel, da 2048 a 4096). Con entrambi a 0, alcune foto vengono prima sondate: dove una tessitura debole e poco contrastata (campi arati) lascia loro poche feature, il primo passaggio ne prende 8192 più deboli, fino al doppio della dimensione se serve (il log lo dice). Le feature invarianti affini aiutano con le prese oblique e sono più lente.
Focale e Larghezza del sensore: orientamento interno quando manca l'EXIF (pellicola scansionata): la focale e la larghezza del lato lungo del fotogramma, in millimetri (0 = dall'EXIF / sconosciuta).
File di calibrazione della camera: l'orientamento interno di una camera calibrata (YAML/JSON di ArchaeoOrtho, parametri interni di Orthority, OpenCV, COLMAP cameras.txt o XML di Metashape); più camere sono assegnate alle foto secondo i loro modelli di nome, il modello della camera o la dimensione dell'immagine; una foto di altra risoluzione la riceve scalata. Un file che non si può leggere ferma l'elaborazione prima di ogni lavoro, indicando file, riga e campo.
Orientamento interno: cosa le compensazioni possono cambiare di una camera: 'fixed' mantiene i valori dati attraverso l'allineamento e la georeferenziazione (anche con il controllo automatico), 'refined' lascia che la georeferenziazione li affini con le deviazioni standard della calibrazione come informazione a priori, 'estimated' si autocalibra a partire da essi. 'auto' è 'fixed' dove è data una calibrazione (il file, o scansioni di pellicola raddrizzate da 'Prepara immagini') e 'estimated' altrove; un 'adjust' proprio di una camera nel file ha la precedenza. Con 'fixed' o 'refined' e senza file, la lunghezza focale e la larghezza del sensore sono i valori dati. Il registro, sfm/alignment.json e il rapporto di accuratezza dicono per ogni camera cosa è stato mantenuto.
Metodo di ricostruzione (avanzato): 'incremental' (COLMAP, predefinito) o 'global' (GLOMAP: media delle rotazioni e posizionamento globale, spesso più veloce su blocchi grandi; un annullamento ha effetto solo al termine).
Riprova le immagini escluse (avanzato, attivo): le immagini che le impostazioni rapide escludono, o un blocco diviso in parti, vengono riprovate con caratteristiche più ricche (più deboli per fotogrammi a basso contrasto, affini per oblique ripide) e più coppie; il registro e sfm/alignment.json dicono cosa è stato riprovato e perché.</translation>
    </message>
</context>
<context>
    <name>ArchaeoOrthoPlugin</name>
    <message>
        <location filename="../plugin.py" line="101"/>
        <source>Ground control (GCP dock)</source>
        <translation>Punti d'appoggio (pannello GCP)</translation>
    </message>
    <message>
        <location filename="../plugin.py" line="105"/>
        <source>ArchaeoOrtho: pick ground control points on the map and in the photos</source>
        <translation>ArchaeoOrtho: misura i punti d'appoggio sulla mappa e nelle foto</translation>
    </message>
    <message>
        <location filename="../plugin.py" line="188"/>
        <source>&amp;ArchaeoOrtho</source>
        <translation>&amp;ArchaeoOrtho</translation>
    </message>
</context>
<context>
    <name>ArchaeoOrthoProvider</name>
    <message>
        <location filename="../processing_provider/provider.py" line="17"/>
        <source>ArchaeoOrtho photogrammetry</source>
        <translation>ArchaeoOrtho fotogrammetria</translation>
    </message>
</context>
<context>
    <name>AutoControlAlgorithm</name>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Aligned workspace</source>
        <translation>Area di lavoro allineata</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Reference orthophoto</source>
        <translation>Ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Reference DSM</source>
        <translation>DSM di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Rough position</source>
        <translation>Posizione approssimativa</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>auto</source>
        <translation>automatica</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>EXIF GPS</source>
        <translation>GPS EXIF</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>none</source>
        <translation>nessuna</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="74"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="75"/>
        <source>Camera centres (world)</source>
        <translation>Centri di presa (mondo)</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="76"/>
        <source>Automatic GCPs kept</source>
        <translation>GCP automatici mantenuti</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="77"/>
        <source>Matches found</source>
        <translation>Corrispondenze trovate</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="133"/>
        <source>outlier left out: {}</source>
        <translation>valore anomalo escluso: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Automatic control from a reference orthophoto</source>
        <translation>Punti di controllo automatici da un'ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Reference resolution for web layers (m, 0: auto)</source>
        <translation>Risoluzione di riferimento per layer web (m, 0: auto)</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Area to fetch from web layers</source>
        <translation>Area da scaricare dai layer web</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="121"/>
        <source>Reference DSM {} given without a reference orthophoto (DEM control) must be a raster file on disk; a web layer is fetched only with a reference orthophoto</source>
        <translation>Il DSM di riferimento {} fornito senza ortofoto di riferimento (controllo DEM) deve essere un file raster su disco; un layer web viene scaricato solo con un'ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="125"/>
        <source>A reference DSM alone (DEM control) places the block by the photos&apos; EXIF GPS: choose Rough position auto or EXIF GPS, or give a reference orthophoto as well</source>
        <translation>Un DSM di riferimento da solo (controllo DEM) posiziona il blocco con il GPS EXIF delle foto: scegli Posizione approssimativa automatica o GPS EXIF, oppure fornisci anche un'ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Georeferences an aligned block with no hand-picked ground control: a provisional orthophoto of the block is matched to a reference orthophoto (a national orthophoto, an earlier block's orthomosaic) at a common resolution, each match is found again in the photos and takes its height from the reference DSM, and these automatic GCPs enter the usual GCP-constrained adjustment, which leaves out the outliers. Changes between the two dates (crops, cars, new buildings, another sun) are tolerated: what stays is used, and the log says how many matches survived each step.

Aligned workspace: the block to georeference (its photos must still be where the alignment found them).
Reference orthophoto: any north-up raster, grey or colour, in any CRS (a national one without an EPSG code too); the result is in its CRS (a geographic or Web Mercator file: in the UTM zone of its centre). A layer that is no local file (WMS, XYZ, WCS, a virtual raster) is saved for the block's extent to georef/reference-ortho.tif (a Web Mercator or geographic one in the DSM's CRS, else the UTM zone's).
Reference DSM: a DSM or DTM covering the block, in any CRS and resolution (a 10-30 m DEM too: each height weighs by the DEM's slope and roughness there), heights in metres or in the unit the raster declares (a WCS layer is saved to georef/reference-dsm.tif).
A reference DSM alone (no orthophoto, a raster file on disk) is enough: the block is placed by the photos' EXIF GPS, then co-registered to the DSM (shift, tilt, dome: Nuth &amp; Kääb on the sparse points), and DEM-derived control points enter the adjustment (georef/dem_control.json; the same as Georeference with a reference DSM alone).
Rough position: the photos' EXIF GPS when at least two carry it (auto), always (EXIF GPS), or never (none: rotation and scale are searched over the whole reference, which then should not be much larger than the block).
Reference resolution: metres per pixel a web layer is saved at (0: 0.25 m; the DSM at twice that, at least 0.5 m). Area to fetch: the extent a web layer is saved for; empty: the photos' EXIF GPS positions plus a margin, else the other reference's extent.
Outputs: the camera centres in the reference CRS, the number of automatic GCPs the adjustment kept, the matches found; georef/autocontrol.json lists every candidate with why it was kept or dropped.</source>
        <translation>Georeferenzia un blocco allineato senza punti di controllo scelti a mano: un'ortofoto provvisoria del blocco viene abbinata a un'ortofoto di riferimento (un'ortofoto nazionale, l'ortomosaico di un blocco precedente) a una risoluzione comune, ogni corrispondenza viene ritrovata nelle foto e prende la quota dal DSM di riferimento, e questi GCP automatici entrano nella consueta compensazione vincolata ai GCP, che esclude i valori anomali. I cambiamenti tra le due date (colture, auto, nuovi edifici, un altro sole) sono tollerati: si usa ciò che resta, e il registro dice quante corrispondenze hanno superato ogni passo.

Area di lavoro allineata: il blocco da georeferenziare (le sue foto devono trovarsi ancora dove l'allineamento le ha trovate).
Ortofoto di riferimento: un raster qualsiasi orientato a nord, in scala di grigi o a colori, in un SR qualsiasi (anche uno nazionale senza codice EPSG); il risultato è nel suo SR (un file geografico o Web Mercator: in quello della zona UTM del suo centro). Un layer che non è un file locale (WMS, XYZ, WCS, un raster virtuale) viene salvato per l'estensione del blocco in georef/reference-ortho.tif (uno Web Mercator o geografico nel SR del DSM, altrimenti in quello della zona UTM).
DSM di riferimento: un DSM o DTM che copre il blocco, in un SR e a una risoluzione qualsiasi (anche un DEM da 10-30 m: ogni quota pesa secondo la pendenza e la rugosità del DEM in quel punto), quote in metri o nell'unità che il raster dichiara (un layer WCS viene salvato in georef/reference-dsm.tif).
Un DSM di riferimento da solo (senza ortofoto, un file raster su disco) è sufficiente: il blocco viene posizionato con il GPS EXIF delle foto, poi co-registrato sul DSM (traslazione, inclinazione, cupola: Nuth &amp; Kääb sui punti sparsi), e punti d'appoggio derivati dal DEM entrano nella compensazione (georef/dem_control.json; lo stesso di Georeferenzia con un DSM di riferimento da solo).
Posizione approssimativa: il GPS EXIF delle foto quando almeno due lo hanno (automatica), sempre (GPS EXIF) o mai (nessuna: rotazione e scala vengono cercate su tutto il riferimento, che allora non dovrebbe essere molto più grande del blocco).
Risoluzione di riferimento: metri per pixel con cui si salva un layer web (0: 0,25 m; il DSM al doppio, almeno 0,5 m). Area da scaricare: l'estensione per cui si salva un layer web; vuota: le posizioni GPS EXIF delle foto più un margine, altrimenti l'estensione dell'altro riferimento.
Output: i centri di presa nel SR del riferimento, il numero di GCP automatici mantenuti dalla compensazione, le corrispondenze trovate; georef/autocontrol.json elenca ogni candidato con il motivo per cui è stato mantenuto o scartato.</translation>
    </message>
</context>
<context>
    <name>BuildDsmAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Workspace folder (georeferenced)</source>
        <translation>Cartella dell'area di lavoro (georeferenziata)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>DSM resolution in metres (0 = automatic)</source>
        <translation>Risoluzione del DSM in metri (0 = automatica)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Matching quality (image scale)</source>
        <translation>Qualità della corrispondenza (scala dell'immagine)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Engine</source>
        <translation>Motore di calcolo</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Parallel workers (0 = one per core)</source>
        <translation>Processi paralleli (0 = uno per core)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="63"/>
        <source>Point cloud (LAS)</source>
        <translation>Nuvola di punti (LAS)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="66"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="67"/>
        <source>Share of DSM cells with data inside the camera centres&apos; convex hull</source>
        <translation>Frazione delle celle del DSM con dati entro l'inviluppo convesso dei centri di presa</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="69"/>
        <source>Stereo pairs matched</source>
        <translation>Coppie stereo elaborate</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="70"/>
        <source>Fused points</source>
        <translation>Punti fusi</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="87"/>
        <source>DSM {} ({} m cells), valid fraction {}</source>
        <translation>DSM {} (celle di {} m), frazione valida {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build DSM</source>
        <translation>Genera DSM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Dask scheduler address (empty = this computer, or $ARCHAEOORTHO_DASK_SCHEDULER)</source>
        <translation>Indirizzo dello scheduler Dask (vuoto = questo computer, oppure $ARCHAEOORTHO_DASK_SCHEDULER)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Dense matching of the georeferenced block and a digital surface model (DSM).

Stereo pairs are chosen from the sparse model (shared tie points, baseline-to-depth ratio, viewing angle); each pair is undistorted and rectified from the known poses and matched with semi-global matching (OpenCV SGBM) with a left-right check; a pixel is kept where at least two independent pairs agree. The fused points are rasterised (median of the highest height cluster per cell), small holes are filled and large ones left nodata.

Workspace folder: a georeferenced workspace (run &apos;Georeference&apos; first: a DSM needs a metric scale and a vertical direction, so a workspace that is only aligned is refused).
DSM resolution: DSM cell size in metres; 0 = about twice the median ground sample distance.
Matching quality: image scale for matching (full, half, quarter): half is four times faster than full.
Engine: cpu (default); cuda runs COLMAP patch-match stereo where pycolmap was built with CUDA.
DSM: Cloud-Optimized GeoTIFF, float32 with nodata (default: &lt;workspace&gt;/dsm.tif).
Point cloud: optional LAS file (XYZ + RGB, workspace CRS).
Dask scheduler (advanced): run the stereo pairs on a Dask cluster (tcp://host:8786) whose workers see the workspace path; empty = this computer (or the ARCHAEOORTHO_DASK_SCHEDULER environment variable).

A re-run after a cancel resumes, reusing the pairs already matched in &lt;workspace&gt;/dense/.</source>
        <translation>Corrispondenza densa del blocco georeferenziato e un modello digitale della superficie (DSM).

Le coppie stereo sono scelte dal modello sparso (punti di legame comuni, rapporto base/distanza, angolo di vista); ogni coppia è corretta dalla distorsione e rettificata dagli orientamenti noti e abbinata con semi-global matching (OpenCV SGBM) con controllo sinistra-destra; un pixel è tenuto dove almeno due coppie indipendenti concordano. I punti fusi sono rasterizzati (mediana del gruppo di quote più alto per cella), i piccoli vuoti riempiti e quelli grandi lasciati nodata.

Cartella dell'area di lavoro: un'area di lavoro georeferenziata (eseguire prima 'Georeferenzia': un DSM richiede una scala metrica e una verticale, quindi un'area di lavoro solo orientata viene rifiutata).
Risoluzione del DSM: dimensione della cella del DSM in metri; 0 = circa il doppio del GSD mediano.
Qualità della corrispondenza: scala dell'immagine per la corrispondenza (piena, metà, quarto): metà è quattro volte più veloce di piena.
Motore di calcolo: cpu (predefinito); cuda esegue lo stereo patch-match di COLMAP dove pycolmap è compilato con CUDA.
DSM: Cloud-Optimized GeoTIFF, float32 con nodata (predefinito: &lt;workspace&gt;/dsm.tif).
Nuvola di punti: file LAS facoltativo (XYZ + RGB, SR dell'area di lavoro).
Scheduler Dask (avanzato): calcola le coppie stereo su un cluster Dask (tcp://host:8786) i cui worker vedono il percorso dello spazio di lavoro; vuoto = questo computer (o la variabile d'ambiente ARCHAEOORTHO_DASK_SCHEDULER).

Una nuova esecuzione dopo un annullamento riprende: le coppie già elaborate sono riutilizzate da &lt;workspace&gt;/dense/.</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="61"/>
        <source>DSM</source>
        <translation>DSM</translation>
    </message>
</context>
<context>
    <name>BuildDtmAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="53"/>
        <source>Workspace folder</source>
        <translation>Cartella dell'area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Contour interval in metres (0 = none)</source>
        <translation>Equidistanza delle curve di livello in metri (0 = nessuna)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Ground filter slope (rise over run)</source>
        <translation>Pendenza del filtro del terreno (dislivello su distanza)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Largest object radius in metres</source>
        <translation>Raggio massimo degli oggetti in metri</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Height above ground of an object in metres</source>
        <translation>Altezza di un oggetto sul terreno in metri</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="70"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="71"/>
        <source>DTM source</source>
        <translation>Origine del DTM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="72"/>
        <source>Classified point cloud</source>
        <translation>Nuvola di punti classificata</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="73"/>
        <source>Share of DSM cells on the ground</source>
        <translation>Frazione delle celle del DSM sul terreno</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="74"/>
        <source>Share of DTM cells interpolated</source>
        <translation>Frazione delle celle del DTM interpolate</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="97"/>
        <source>Give a workspace folder, or a DSM file and where to write the DTM</source>
        <translation>Indica una cartella dell'area di lavoro, oppure un file DSM e dove scrivere il DTM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build DTM</source>
        <translation>Genera DTM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>DSM file</source>
        <translation>File DSM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="65"/>
        <source>DTM</source>
        <translation>DTM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="67"/>
        <source>Contours</source>
        <translation>Curve di livello</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>A digital terrain model (bare earth) from the DSM: buildings, trees and crops removed, the ground interpolated under them.

The ground filter is SMRF (Pingel et al. 2013, the algorithm of PDAL&apos;s filters.smrf) on the DSM&apos;s grid; under each removed object the ground is a thin-plate spline through the ground around it. The DTM is a Cloud-Optimized GeoTIFF on the DSM&apos;s exact grid; beside it terrain/dtm-source.tif says which cells are measured ground (1) and which interpolated (2). The DSM stage&apos;s point cloud, if it wrote one, is copied with ASPRS classes 2 (ground) and 1 (unclassified) to terrain/points-classified.las.

Workspace folder: a workspace with a DSM (optional when a DSM file is given).
DSM file: any DSM in a projected CRS (metres); default: the workspace&apos;s.
Contour interval: contour lines every this many metres into a GeoPackage (0 = none).
Slope, largest object radius and height threshold (advanced): SMRF&apos;s parameters (PDAL&apos;s defaults).
DTM: where to write it (default: &lt;workspace&gt;/dtm.tif).
Contours: where to write the contour lines (default: &lt;workspace&gt;/terrain/contours.gpkg).</source>
        <translation>Un modello digitale del terreno (suolo nudo) dal DSM: edifici, alberi e colture rimossi, il terreno interpolato sotto di essi.

Il filtro del terreno è SMRF (Pingel et al. 2013, l'algoritmo di filters.smrf di PDAL) sulla griglia del DSM; sotto ogni oggetto rimosso il terreno è una thin-plate spline attraverso il terreno intorno. Il DTM è un Cloud-Optimized GeoTIFF esattamente sulla griglia del DSM; accanto, terrain/dtm-source.tif indica quali celle sono terreno misurato (1) e quali interpolate (2). La nuvola di punti della fase DSM, se ne ha scritta una, è copiata con le classi ASPRS 2 (terreno) e 1 (non classificato) in terrain/points-classified.las.

Cartella dell'area di lavoro: un'area di lavoro con DSM (facoltativa se è indicato un file DSM).
File DSM: qualsiasi DSM in un SR proiettato (metri); predefinito: quello dell'area di lavoro.
Equidistanza: curve di livello ogni tanti metri in un GeoPackage (0 = nessuna).
Pendenza, raggio massimo degli oggetti e soglia di altezza (avanzati): i parametri di SMRF (i valori predefiniti di PDAL).
DTM: dove scriverlo (predefinito: &lt;workspace&gt;/dtm.tif).
Curve di livello: dove scrivere le curve di livello (predefinito: &lt;workspace&gt;/terrain/contours.gpkg).</translation>
    </message>
</context>
<context>
    <name>BuildModelAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Workspace folder (with a DSM)</source>
        <translation>Cartella dell'area di lavoro (con un DSM)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Geometry</source>
        <translation>Geometria</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Face budget (triangles at most)</source>
        <translation>Budget di facce (al massimo tanti triangoli)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Files</source>
        <translation>File</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Texture from the photos</source>
        <translation>Texture dalle foto</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Atlas size in pixels (a power of two)</source>
        <translation>Dimensione dell'atlante in pixel (una potenza di due)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Number of atlases at most</source>
        <translation>Numero massimo di atlanti</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="76"/>
        <source>Model folder</source>
        <translation>Cartella del modello</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="78"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="79"/>
        <source>Model (GLB)</source>
        <translation>Modello (GLB)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="80"/>
        <source>Model (OBJ)</source>
        <translation>Modello (OBJ)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="81"/>
        <source>3D Tiles (tileset.json)</source>
        <translation>3D Tiles (tileset.json)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="82"/>
        <source>Faces</source>
        <translation>Facce</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="83"/>
        <source>Share of faces textured</source>
        <translation>Quota di facce con texture</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="114"/>
        <source>3-D model in {}: {} faces, {:.0%} textured</source>
        <translation>Modello 3D in {}: {} facce, {:.0%} con texture</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="118"/>
        <source>{} opens in {}</source>
        <translation>{} si apre in {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="120"/>
        <source>QGIS {} has no 3D Tiles layers (QGIS 3.34 or newer has): open {} there or in CesiumJS, or model.glb in a glTF viewer</source>
        <translation>QGIS {} non ha layer 3D Tiles (QGIS 3.34 o successivo li ha): apri {} lì o in CesiumJS, oppure model.glb in un visualizzatore glTF</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build 3-D model</source>
        <translation>Genera modello 3D</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>A textured 3-D model of the site. The DSM&apos;s surface becomes a triangle mesh within a face budget, each face textured from the photo that sees it best; it is written as a textured OBJ (+ MTL + JPEG atlases), a binary glTF (GLB, texture embedded), a PLY of the geometry and OGC 3D Tiles (tileset.json with levels of detail), all in the workspace CRS about a local origin that the files name.

On QGIS 3.34 or newer the 3D Tiles open as a tiled scene layer in the workspace&apos;s group (View &gt; 3D Map View shows them over the orthomosaic); on older QGIS the log names the files and the programs that open them. A block without control (a model frame) is written as OBJ / GLB / PLY in that frame; 3D Tiles need a georeferenced block.

Workspace folder: a georeferenced workspace with a DSM (run &apos;Build DSM&apos; first).
Geometry: auto (the DSM&apos;s 2.5-D surface), dsm, or points (the fused dense points&apos; 3-D surface: not available yet).
Face budget: the most triangles the model may have.
Files: the formats to write.
Texture from the photos: off for a grey model (faster).
Atlas size and number of atlases (advanced): the texture images&apos; side in pixels and how many at most.
Model folder: where to write the files (default: &lt;workspace&gt;/model3d; the folder is replaced whole).</source>
        <translation>Un modello 3D con texture del sito. La superficie del DSM diventa una mesh di triangoli entro un budget di facce, ogni faccia con la texture della foto che la vede meglio; è scritto come OBJ con texture (+ MTL + atlanti JPEG), glTF binario (GLB, texture incorporata), PLY della geometria e OGC 3D Tiles (tileset.json con livelli di dettaglio), tutti nel SR dell'area di lavoro attorno a un'origine locale indicata dai file.

Con QGIS 3.34 o successivo i 3D Tiles si aprono come layer di scena a tasselli nel gruppo dell'area di lavoro (Visualizza &gt; Vista mappa 3D li mostra sopra l'ortomosaico); con QGIS più vecchi il registro indica i file e i programmi che li aprono. Un blocco senza punti d'appoggio (un sistema del modello) è scritto come OBJ / GLB / PLY in quel sistema; i 3D Tiles richiedono un blocco georeferenziato.

Cartella dell'area di lavoro: un'area di lavoro georeferenziata con un DSM (esegui prima 'Genera DSM').
Geometria: auto (la superficie 2,5D del DSM), dsm o points (la superficie 3D dei punti densi fusi: non ancora disponibile).
Budget di facce: il numero massimo di triangoli del modello.
File: i formati da scrivere.
Texture dalle foto: disattivata per un modello grigio (più veloce).
Dimensione e numero degli atlanti (avanzato): il lato delle immagini di texture in pixel e quante al massimo.
Cartella del modello: dove scrivere i file (predefinita: &lt;workspace&gt;/model3d; la cartella è sostituita per intero).</translation>
    </message>
</context>
<context>
    <name>BuildOrthophotoAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="107"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="108"/>
        <source>Share of mosaic cells with data</source>
        <translation>Frazione delle celle del mosaico con dati</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="109"/>
        <source>Resolution used</source>
        <translation>Risoluzione usata</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="110"/>
        <source>Images in the mosaic</source>
        <translation>Immagini nel mosaico</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build orthophoto</source>
        <translation>Genera ortofoto</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Georeferenced workspace</source>
        <translation>Area di lavoro georeferenziata</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>DSM</source>
        <translation>DSM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Images</source>
        <translation>Immagini</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Seam blending</source>
        <translation>Sfumatura delle giunzioni</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Resampling</source>
        <translation>Ricampionamento</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Parallel tile workers</source>
        <translation>Processi paralleli per tessera</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Dask scheduler</source>
        <translation>Scheduler Dask</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="99"/>
        <source>Orthomosaic</source>
        <translation>Ortomosaico</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="102"/>
        <source>Per-image orthophotos folder</source>
        <translation>Cartella delle ortofoto per immagine</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="105"/>
        <source>Seamlines</source>
        <translation>Linee di giunzione</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Seamlines to follow</source>
        <translation>Linee di giunzione da seguire</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="136"/>
        <source>Seamlines must be a GeoPackage (.gpkg) file, got {}</source>
        <translation>Le linee di giunzione devono essere un file GeoPackage (.gpkg), ricevuto {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Far-field limit (× best ground resolution, 0 = off)</source>
        <translation>Limite del campo lontano (× miglior risoluzione al suolo, 0 = spento)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Even out vignetting and hot spot</source>
        <translation>Compensa vignettatura e hot spot</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>True orthophotos and the orthomosaic of a georeferenced workspace.

Every cell takes its height from the DSM and is projected through the full camera model (pose, focal length, principal point, lens distortion) into the images. A cell hidden from an image by higher surface (a wall, a tree, a hill) is left out of that image, so buildings do not lean and nothing appears twice; the mosaic fills it from an image that sees it. Each part of the mosaic comes from the image that looks at it most vertically and closest to its centre; seamlines go around buildings and trees; brightness differences between images are evened out and seams blended.

Georeferenced workspace: a workspace with a DSM (run &apos;Build DSM&apos; first), or give a DSM.
DSM: optional raster (e.g. an ALS DSM, in any CRS: reprojected on the fly); default the workspace DSM.
Images: a subset, e.g. &apos;DJI_00*.JPG&apos;, &apos;IMG_0012.tif, IMG_0013.tif&apos;, &apos;group:2&apos; or &apos;group:NIR&apos; (a camera group by id or by make/model), &apos;!name&apos; to leave one out. Empty: all images.
Resolution: cell size in CRS units; 0 = the images&apos; ground sample distance.
Seam blending: feather (a ramp across seams), multiband (Laplacian pyramid: no visible seam in brightness and no ghosting), none (hard cut).
Even out vignetting and hot spot: the darkening towards the photos&apos; corners, the bright patch opposite the sun and the exposure of each photo are measured where the photos overlap and removed, then a smooth gain per photo levels the seams, so photos taken at different times meet without a brightness step (used only where it makes the overlaps agree better; off: one exposure gain per photo).
Far-field limit (advanced): each image is used only where its ground resolution is within this factor of its best, so the stretched far field of an oblique (towards the horizon) is left out and the mosaic takes those cells from a nearer view; cells no image sees finely enough stay empty. 0 = off (default 3).
Orthomosaic: Cloud-Optimized GeoTIFF with overviews, the images&apos; bands and data type (8/16 bit kept) plus an alpha band (default &lt;workspace&gt;/orthomosaic.tif).
Per-image orthophotos folder: optional folder for one true orthophoto per image (COG).
Seamlines: optional GeoPackage of polygons naming the image each part of the mosaic comes from (one polygon per image, its name in the field &apos;image&apos;); edit it to move a seam.
Seamlines to follow: optional edited seamlines (polygons with the field &apos;image&apos;, in the mosaic&apos;s CRS): where a polygon names an image, the mosaic takes that image where it sees the ground (the log says where it does not); automatic seams elsewhere. Reshape a polygon, or draw one and name its image, to move a seam off a crop mark or a moving car, and run again.
Dask scheduler (advanced): render the tiles on a Dask cluster (tcp://host:8786) whose workers see the workspace path; empty = this computer, or $ARCHAEOORTHO_DASK_SCHEDULER.</source>
        <translation>Ortofoto vere e l'ortomosaico di un'area di lavoro georeferenziata.

Ogni cella prende la quota dal DSM ed è proiettata nelle immagini con il modello completo della camera (orientamento, focale, punto principale, distorsione dell'obiettivo). Una cella nascosta in un'immagine da una superficie più alta (un muro, un albero, una collina) viene esclusa da quell'immagine, così gli edifici non pendono e nulla compare due volte; il mosaico la riempie da un'immagine che la vede. Ogni parte del mosaico proviene dall'immagine che la guarda nel modo più verticale e più vicino al suo centro; le linee di giunzione girano attorno a edifici e alberi; le differenze di luminosità tra le immagini sono compensate e le giunzioni sfumate.

Area di lavoro georeferenziata: un'area di lavoro con DSM (eseguire prima 'Genera DSM'), oppure indicare un DSM.
DSM: raster facoltativo (ad es. un DSM ALS, in qualsiasi SR: riproiettato al volo); predefinito il DSM dell'area di lavoro.
Immagini: un sottoinsieme, ad es. 'DJI_00*.JPG', 'IMG_0012.tif, IMG_0013.tif', 'group:2' o 'group:NIR' (un gruppo di camere per numero o per marca/modello), '!nome' per escluderne una. Vuoto: tutte le immagini.
Risoluzione: dimensione della cella in unità del SR; 0 = il GSD delle immagini.
Sfumatura delle giunzioni: feather (rampa attraverso le giunzioni), multiband (piramide laplaciana: nessuna giunzione visibile nella luminosità e nessun effetto fantasma), none (taglio netto).
Compensa vignettatura e hot spot: l'oscuramento verso gli angoli delle foto, la macchia chiara opposta al sole e l'esposizione di ogni foto sono misurati dove le foto si sovrappongono e rimossi, poi un guadagno regolare per foto livella le giunzioni, così foto scattate in momenti diversi si uniscono senza salti di luminosità (applicato solo dove le sovrapposizioni concordano meglio; disattivato: un guadagno di esposizione per foto).
Limite del campo lontano (avanzato): ogni immagine è usata solo dove la sua risoluzione al suolo è entro questo fattore della sua migliore, così il campo lontano allungato di una foto obliqua (verso l'orizzonte) è escluso e il mosaico prende quelle celle da una vista più vicina; le celle che nessuna immagine vede abbastanza finemente restano vuote. 0 = spento (predefinito 3).
Ortomosaico: Cloud-Optimized GeoTIFF con panoramiche, le bande e il tipo di dato delle immagini (8/16 bit conservati) più una banda alfa (predefinito &lt;workspace&gt;/orthomosaic.tif).
Cartella delle ortofoto per immagine: cartella facoltativa per un'ortofoto vera per immagine (COG).
Linee di giunzione: GeoPackage facoltativo di poligoni che indicano l'immagine da cui proviene ogni parte del mosaico (un poligono per immagine, il suo nome nel campo 'image'); modificarlo per spostare una giunzione.
Linee di giunzione da seguire: linee di giunzione modificate facoltative (poligoni con il campo 'image', nel SR del mosaico): dove un poligono indica un'immagine, il mosaico usa quell'immagine dove vede il terreno (il registro dice dove no); altrove giunzioni automatiche. Rimodellare un poligono, o disegnarne uno e indicarne l'immagine, per spostare una giunzione da una traccia nelle colture o da un'auto in movimento, ed eseguire di nuovo.
Scheduler Dask (avanzato): calcola le tessere su un cluster Dask (tcp://host:8786) i cui worker vedono il percorso dell'area di lavoro; vuoto = questo computer, oppure $ARCHAEOORTHO_DASK_SCHEDULER.</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Resolution (CRS units, 0 = GSD)</source>
        <translation>Risoluzione (unità del SR, 0 = GSD)</translation>
    </message>
</context>
<context>
    <name>Choices</name>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>auto</source>
        <translation>automatica (auto)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>exhaustive</source>
        <translation>tutte le coppie (exhaustive)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>sequential</source>
        <translation>sequenziale (sequential)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>spatial</source>
        <translation>spaziale (spatial)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>incremental</source>
        <translation>incrementale (incremental)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>global</source>
        <translation>globale (global)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>fixed</source>
        <translation>fisso (fixed)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>refined</source>
        <translation>affinato (refined)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>estimated</source>
        <translation>stimato (estimated)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>full</source>
        <translation>piena (full)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>half</source>
        <translation>metà (half)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>quarter</source>
        <translation>un quarto (quarter)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>feather</source>
        <translation>sfumata (feather)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>multiband</source>
        <translation>multibanda (multiband)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>none</source>
        <translation>nessuna (none)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>bilinear</source>
        <translation>bilineare (bilinear)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cubic</source>
        <translation>cubica (cubic)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>nearest</source>
        <translation>vicino più prossimo (nearest)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cross</source>
        <translation>croce (cross)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dot</source>
        <translation>punto (dot)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ring_dot</source>
        <translation>punto in un anello (ring_dot)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cross_ring</source>
        <translation>croce in un anello (cross_ring)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>corners</source>
        <translation>angoli (corners)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>sides</source>
        <translation>metà dei lati (sides)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>eight</source>
        <translation>otto (eight)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Sky-view factor</source>
        <translation>Fattore di vista del cielo (sky-view factor)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Openness (positive)</source>
        <translation>Apertura (positiva)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Openness (negative)</source>
        <translation>Apertura (negativa)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Simple local relief model</source>
        <translation>Modello semplice del rilievo locale</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Multi-scale relief model</source>
        <translation>Modello del rilievo multiscala</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Multi-direction hillshade</source>
        <translation>Ombreggiatura da più direzioni</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Local dominance</source>
        <translation>Dominanza locale</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>VAT (visualisation for archaeological topography, blend)</source>
        <translation>VAT (visualizzazione per la topografia archeologica, fusione)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>raw</source>
        <translation>grezzo (raw)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>normalised</source>
        <translation>normalizzato (normalised)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>irradiance</source>
        <translation>irradianza (irradiance)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>checkerboard</source>
        <translation>scacchiera (checkerboard)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>circle</source>
        <translation>cerchio (circle)</translation>
    </message>
</context>
<context>
    <name>ContoursAlgorithm</name>
    <message>
        <location filename="../processing_provider/contours.py" line="30"/>
        <source>Elevation raster</source>
        <translation>Raster delle quote</translation>
    </message>
    <message>
        <location filename="../processing_provider/contours.py" line="30"/>
        <source>Interval in metres</source>
        <translation>Equidistanza in metri</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Contours</source>
        <translation>Curve di livello</translation>
    </message>
    <message>
        <location filename="../processing_provider/contours.py" line="37"/>
        <source>Contour lines</source>
        <translation>Curve di livello</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Contour lines of a DTM or DSM at a chosen interval (GDAL&apos;s contour generator) into a GeoPackage layer &apos;contours&apos; whose &apos;elevation&apos; field labels them.

Elevation raster: a DTM or DSM in a projected CRS (metres).
Interval: metres between two contour lines (e.g. 0.5).
Contours: the GeoPackage to write.</source>
        <translation>Curve di livello di un DTM o DSM a un'equidistanza scelta (il generatore di curve di livello di GDAL) in un layer GeoPackage 'contours' il cui campo 'elevation' le etichetta.

Raster delle quote: un DTM o DSM in un SR proiettato (metri).
Equidistanza: metri tra due curve di livello (ad es. 0.5).
Curve di livello: il GeoPackage da scrivere.</translation>
    </message>
</context>
<context>
    <name>CoreMessages</name>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>captures: {} multi-band photo(s) of {}{} in {} ({} radiometry)</source>
        <translation>acquisizioni: {} foto multibanda da {}{} in {} (radiometria {})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pipeline done</source>
        <translation>elaborazione completata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{}: an RGB frame of a capture not stacked (a calibration panel&apos;s, or left out): not aligned</source>
        <translation>{}: un fotogramma RGB di un'acquisizione non impilata (di un pannello di calibrazione o esclusa): non allineato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>--- stage {} ---</source>
        <translation>--- fase {} ---</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>prepare: {} sky mask(s), {} of {} photos kept</source>
        <translation>preparazione: {} maschere del cielo, {} di {} foto mantenute</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>find targets: {} of {} targets found, {} observations</source>
        <translation>trova i target: {} di {} target trovati, {} osservazioni</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>find targets: {}</source>
        <translation>trova i target: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {} ({} image(s), {} x {} px): interior orientation {}</source>
        <translation>camera {} ({} immagini, {} x {} px): orientamento interno {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: the calibration {} gives a focal length of {} px, {} {} px ({} %); the calibration&apos;s is used: check that it is this camera&apos;s and that its units are right</source>
        <translation>camera {}: la calibrazione {} dà una focale di {} px, {} {} px ({} %); si usa quella della calibrazione: verifica che sia di questa camera e che le sue unità siano corrette</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>calibration {}, {}: {}</source>
        <translation>calibrazione {}, {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>calibration file {}: no photo matches {}; it is not used</source>
        <translation>file di calibrazione {}: nessuna foto corrisponde a {}; non è usato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>not registered: {}: {}</source>
        <translation>non registrata: {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation round {}: matching {} pairs</source>
        <translation>ciclo di estensione {}: abbinamento di {} coppie</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation round {}: {}: {}</source>
        <translation>ciclo di estensione {}: {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation: {} image(s) without any verified pair after round 1, not escalated further (no ground shared with the block): {}</source>
        <translation>estensione: {} immagini senza alcuna coppia verificata dopo il ciclo 1, non estese oltre (nessun terreno in comune con il blocco): {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation round {}: could not put {} back ({}); a re-run extracts the features of the images of this round again</source>
        <translation>ciclo di estensione {}: impossibile ripristinare {} ({}); una nuova esecuzione estrae di nuovo le caratteristiche delle immagini di questo ciclo</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>features: {} images already extracted, reused</source>
        <translation>caratteristiche: {} immagini già estratte, riusate</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>features: {}/{} images ({})</source>
        <translation>caratteristiche: {}/{} immagini ({})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>matching: {} of {} pairs already matched, reused</source>
        <translation>abbinamento: {} di {} coppie già abbinate, riusate</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>matching: {}/{} pairs</source>
        <translation>abbinamento: {}/{} coppie</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: {} {} {}x{}, {}, {} images</source>
        <translation>camera {}: {} {} {}x{}, {}, {} immagini</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>joining {} components by the photos&apos; positions (fits {} m, photo spacing {} m)</source>
        <translation>unione di {} componenti tramite le posizioni delle foto (adattamento {} m, distanza tra le foto {} m)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>join: {}</source>
        <translation>unione: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>join: registered on the joined block&apos;s points: {}</source>
        <translation>unione: registrate sui punti del blocco unito: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: {} image(s) outside the main block of {}; trying them against the finished block with {} 2D-3D inliers (first pass: {})</source>
        <translation>mappatura: {} immagini fuori dal blocco principale di {}; prova contro il blocco finito con {} inlier 2D-3D (primo passaggio: {})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: {} more image(s) registered on the relaxed threshold: {}</source>
        <translation>mappatura: {} immagini in più registrate con la soglia rilassata: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: global SfM (rotation averaging, global positioning, bundle adjustment)</source>
        <translation>mappatura: SfM globale (media delle rotazioni, posizionamento globale, compensazione a stelle proiettive)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: global SfM done</source>
        <translation>mappatura: SfM globale completata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: the self-calibrated focal length went from {} to {} px and {} of {} images registered; mapping again with the photos&apos; own focal length and the distortion held</source>
        <translation>mappatura: la focale autocalibrata è passata da {} a {} px e {} di {} immagini sono state registrate; nuova mappatura con la focale delle foto e la distorsione fissata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: the focal length is held at the photos&apos; own ({} px; the distortion refined only by the final adjustment): self-calibrated it drifted to {} px and registered {} of {} images, held {}</source>
        <translation>mappatura: la focale è fissata a quella delle foto ({} px; la distorsione affinata solo dalla compensazione finale): autocalibrata è derivata a {} px registrando {} di {} immagini, fissata {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: two images, mapped with the incremental mapper (the global mapper needs tracks of three or more views)</source>
        <translation>mappatura: due immagini, mappate con il metodo incrementale (quello globale richiede tracce di tre o più viste)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: registered image {}</source>
        <translation>mappatura: immagine {} registrata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: continuing the block of {} images</source>
        <translation>mappatura: prosecuzione del blocco di {} immagini</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: no further image registered</source>
        <translation>mappatura: nessun'altra immagine registrata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: {} {}: left out of the block</source>
        <translation>mappatura: {} {}: escluse dal blocco</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: with the intrinsics held {} images registered: the self-calibrated mapping is kept</source>
        <translation>mappatura: con l'orientamento interno fissato {} immagini registrate: si mantiene la mappatura autocalibrata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>final bundle adjustment: {} {}: left out of the block</source>
        <translation>compensazione finale: {} {}: escluse dal blocco</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>masks: {} of {} images have a mask ({}): no features where they are black</source>
        <translation>maschere: {} di {} immagini hanno una maschera ({}): nessuna caratteristica dove sono nere</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>features: {} photo(s) matched on an 8-bit image of their primary band or grey ({})</source>
        <translation>caratteristiche: {} foto abbinate su un'immagine a 8 bit della loro banda principale o in grigio ({})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>aligned {}/{} images, {} px</source>
        <translation>{}/{} immagini allineate, {} px</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pair selection: {}, {} pairs for {} images</source>
        <translation>selezione delle coppie: {}, {} coppie per {} immagini</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>final bundle adjustment</source>
        <translation>compensazione finale</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM tile {}/{}</source>
        <translation>tassello del DSM {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>matching: {} pairs ({} reused from a previous run), {} s per pair, {} s per megapixel, {}</source>
        <translation>abbinamento: {} coppie ({} riusate da un'esecuzione precedente), {} s per coppia, {} s per megapixel, {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>resuming: {} of {} pairs already matched</source>
        <translation>ripresa: {} di {} coppie già abbinate</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pair {} + {} skipped: {}</source>
        <translation>coppia {} + {} saltata: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} image(s) are in fewer than {} matched pairs and add no points of their own: {}{}</source>
        <translation>{} immagini sono in meno di {} coppie abbinate e non aggiungono punti propri: {}{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>undistorting images (COLMAP)</source>
        <translation>rettifica delle distorsioni delle immagini (COLMAP)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>patch-match stereo (COLMAP, CUDA)</source>
        <translation>stereo patch-match (COLMAP, CUDA)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>stereo fusion (COLMAP)</source>
        <translation>fusione stereo (COLMAP)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pairs: {} selected from {} overlapping image pairs ({} images, quality {}, median GSD {} m, DSM resolution {} m)</source>
        <translation>coppie: {} scelte su {} coppie di immagini sovrapposte ({} immagini, qualità {}, GSD mediana {} m, risoluzione del DSM {} m)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM done</source>
        <translation>DSM completato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>points: {} fused from {} images</source>
        <translation>punti: {} fusi da {} immagini</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>removed {}, left by a killed run</source>
        <translation>rimosso {}, lasciato da un'esecuzione interrotta</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>Helmert from {} {}</source>
        <translation>Helmert da {} {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>triangulating control points</source>
        <translation>triangolazione dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>every control point has Z = {}: treated as a placeholder, not a surveyed height; the points are taken to lie near one level surface (sigma Z {} m) and the Z figures measure the departure from that level, not height accuracy</source>
        <translation>ogni punto d'appoggio ha Z = {}: trattato come segnaposto, non come quota rilevata; i punti sono considerati vicini a un'unica superficie piana (sigma Z {} m) e i valori Z misurano lo scostamento da essa, non l'accuratezza in quota</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control points given sigmas far finer than the block resolves at them (about {} m XY, {} m Z) - {}: honoured as given, i.e. these points are held fixed at their coordinates; if they are not exact to that level give their real accuracy (e.g. 0.01 m for RTK)</source>
        <translation>ai punti d'appoggio sono stati dati sigma molto più fini di quanto il blocco li risolva (circa {} m XY, {} m Z) - {}: rispettati come dati, cioè questi punti sono tenuti fissi alle loro coordinate; se non sono esatti a quel livello indica la loro accuratezza reale (ad es. 0,01 m per RTK)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>estimating the accuracy of the control given without sigmas</source>
        <translation>stima dell'accuratezza dei punti d'appoggio dati senza sigma</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the control points&apos; sigma XY ({} m) is far below how well the block fits them: {} control points miss the rigid block by {} m (median, {} sigma), and the adjustment bends the block to fit them; if their coordinates are metre-level (handheld GPS, read off a map) give the file sigma columns of that size, or none: without sigmas their accuracy is estimated from the data</source>
        <translation>il sigma XY dei punti d'appoggio ({} m) è molto al di sotto di come il blocco vi si adatta: {} punti d'appoggio mancano il blocco rigido di {} m (mediana, {} sigma) e la compensazione piega il blocco per adattarlo; se le loro coordinate sono al metro (GPS palmare, lette da una carta) dai al file colonne sigma di quella grandezza, o nessuna: senza sigma la loro accuratezza è stimata dai dati</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>updating the model</source>
        <translation>aggiornamento del modello</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>check points</source>
        <translation>punti di controllo</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>georeferencing done</source>
        <translation>georeferenziazione completata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point not usable: {}</source>
        <translation>punto d'appoggio non utilizzabile: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} camera position(s) without a height (Z): they constrain X and Y only</source>
        <translation>{} posizioni della camera senza quota (Z): vincolano solo X e Y</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point {}: {} m off the Helmert fit of the others, but consistent with the adjusted block ({} sigma, image residuals up to {} px): re-admitted; the block was deformed</source>
        <translation>punto d'appoggio {}: a {} m dall'adattamento di Helmert degli altri, ma coerente con il blocco compensato ({} sigma, residui in immagine fino a {} px): riammesso; il blocco era deformato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no CRS given for the ground control</source>
        <translation>nessun SR indicato per i punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>CRS {} not recognised; assuming metric, right-handed coordinates</source>
        <translation>SR {} non riconosciuto; si assumono coordinate metriche destrorse</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} {} is {} m off the Helmert fit of the others (threshold {} m): excluded; check its coordinates</source>
        <translation>{} {} è a {} m dall'adattamento di Helmert degli altri (soglia {} m): escluso; controllane le coordinate</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point {} is {} m off the Helmert fit of the others (threshold {} m): left out of the first adjustment, then re-tested against the adjusted block</source>
        <translation>il punto d'appoggio {} è a {} m dall'adattamento di Helmert degli altri (soglia {} m): escluso dalla prima compensazione, poi riverificato sul blocco compensato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no 4 control points agree with the block within {} m: either the block is deformed or several coordinates are wrong</source>
        <translation>nessun gruppo di 4 punti d'appoggio concorda con il blocco entro {} m: il blocco è deformato o diverse coordinate sono errate</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point {} disagrees with the others through the block ({} m): suspect, dropped from the adjustment</source>
        <translation>il punto d'appoggio {} è in disaccordo con gli altri attraverso il blocco ({} m): sospetto, escluso dalla compensazione</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} point {}: observation at ({}, {}) lies outside image {} ({} x {} px); ignored</source>
        <translation>punto ({}) {}: l'osservazione a ({}, {}) è fuori dall'immagine {} ({} x {} px); ignorata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the block adjusted with the DEM control could not be co-registered again: {}</source>
        <translation>il blocco compensato con il controllo dal DEM non ha potuto essere coregistrato di nuovo: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>bundle adjustment: {} iteration(s), cost {} -&gt; {}</source>
        <translation>compensazione a stelle proiettive: {} iterazioni, costo {} -&gt; {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera(s) {}: calibrated interior orientation fixed, not refined{}</source>
        <translation>camera/e {}: orientamento interno calibrato fissato, non affinato{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera(s) {}: interior orientation refined with priors at the calibration&apos;s values (weighted by its sigmas)</source>
        <translation>camera/e {}: orientamento interno affinato con vincoli ai valori della calibrazione (pesati con i suoi sigma)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>adjusting {} of {} tie points ({} of {} observations); the others are re-triangulated afterwards</source>
        <translation>compensazione di {} di {} punti di legame ({} di {} osservazioni); gli altri sono ritriangolati dopo</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>bundle adjustment</source>
        <translation>compensazione a stelle proiettive</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: the calibration&apos;s model {} is not the model&apos;s {}: its intrinsics follow refine_intrinsics</source>
        <translation>camera {}: il modello della calibrazione {} non è quello del modello {}: i suoi parametri interni seguono refine_intrinsics</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: only {} image(s), intrinsics kept fixed</source>
        <translation>camera {}: solo {} immagini, parametri interni fissati</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>GCP coordinates measured on upright photos: no photo of the block is stored turned (EXIF orientation 1 or none), nothing to convert</source>
        <translation>coordinate dei GCP misurate su foto raddrizzate: nessuna foto del blocco è salvata ruotata (orientamento EXIF 1 o nessuno), nulla da convertire</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>USE_EXIF_GPS is set but no image carries EXIF GPS</source>
        <translation>USE_EXIF_GPS è impostato ma nessuna immagine ha il GPS EXIF</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>co-registration done</source>
        <translation>coregistrazione completata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>co-registration iteration {}: shift {}, {} m</source>
        <translation>coregistrazione iterazione {}: spostamento {}, {} m</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>georeferenced</source>
        <translation>georeferenziato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reference DEM {} without ground control or camera positions: the photos&apos; EXIF GPS place the block, the DEM fixes its heights, tilt and dome</source>
        <translation>DEM di riferimento {} senza punti d'appoggio né posizioni delle camere: il GPS EXIF delle foto colloca il blocco, il DEM ne fissa quote, inclinazione e curvatura</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>checking the reference DEM against the block</source>
        <translation>verifica del DEM di riferimento rispetto al blocco</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: Jacobian</source>
        <translation>covarianza: jacobiano</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: normal equations</source>
        <translation>covarianza: equazioni normali</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: inverting the reduced system</source>
        <translation>covarianza: inversione del sistema ridotto</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: points</source>
        <translation>covarianza: punti</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance done</source>
        <translation>covarianza completata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>automatic control: point {} of {} in the photos</source>
        <translation>controllo automatico: punto {} di {} nelle foto</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>provisional orthophoto: projecting {}</source>
        <translation>ortofoto provvisoria: proiezione di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>provisional orthophoto: sampling {}</source>
        <translation>ortofoto provvisoria: campionamento di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>first match</source>
        <translation>primo abbinamento</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>looking for targets: {}</source>
        <translation>ricerca dei target: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} candidate(s), {} tied across photos</source>
        <translation>{} candidati, {} collegati tra le foto</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} target(s), {} observation(s) found</source>
        <translation>{} target, {} osservazioni trovate</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reading images</source>
        <translation>lettura delle immagini</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>writing Cloud-Optimized GeoTIFF</source>
        <translation>scrittura del Cloud-Optimized GeoTIFF</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>point cloud: {} points</source>
        <translation>nuvola di punti: {} punti</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>3-D model done</source>
        <translation>modello 3D completato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mesh: {} faces (DSM grid reduced {} x)</source>
        <translation>mesh: {} facce (griglia del DSM ridotta {} volte)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>visibility in {}</source>
        <translation>visibilità in {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>texture from {}</source>
        <translation>texture da {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>3D Tiles: level {} of {}</source>
        <translation>3D Tiles: livello {} di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{}: tile {}/{}</source>
        <translation>{}: tassello {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>orthomosaic done</source>
        <translation>ortomosaico completato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no DSM given: how far planar rectification is off because of relief cannot be measured</source>
        <translation>nessun DSM indicato: non si può misurare quanto la rettifica piana si scosti a causa del rilievo</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the DSM does not cover the image&apos;s ground: planar displacement not measured</source>
        <translation>il DSM non copre il terreno dell'immagine: spostamento planare non misurato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>planar rectification: tile {}/{}</source>
        <translation>rettifica piana: tassello {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mosaic planned</source>
        <translation>mosaico pianificato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>planning the mosaic: {}/{}</source>
        <translation>pianificazione del mosaico: {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: fall-off fitted</source>
        <translation>radiometria: caduta di luce stimata</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: hot spot searched</source>
        <translation>radiometria: hot spot cercato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: gain fields fitted</source>
        <translation>radiometria: campi di guadagno stimati</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: sampling {}/{}</source>
        <translation>radiometria: campionamento {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera at X {} Y {} Z {}, omega {} phi {} kappa {} deg</source>
        <translation>camera a X {} Y {} Z {}, omega {} phi {} kappa {} gradi</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>oriented</source>
        <translation>orientato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the control / DSM CRS is geographic (degrees): {} is oriented and orthorectified in EPSG:{} (the UTM zone of the image), and the orthophoto is written in it</source>
        <translation>il SR dei punti d'appoggio / del DSM è geografico (gradi): {} è orientata e ortorettificata in EPSG:{} (la zona UTM dell'immagine) e l'ortofoto è scritta in esso</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no CRS given: coordinates are taken as they are (no CRS written)</source>
        <translation>nessun SR indicato: le coordinate sono prese come sono (nessun SR scritto)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>GCP observation(s) outside the {} x {} image {}: {}</source>
        <translation>osservazioni di GCP fuori dall'immagine {} x {} {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} orthophoto {}: {} per cell, {} % of its cells with data</source>
        <translation>{} ortofoto {}: {} per cella, {} % delle sue celle con dati</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>done</source>
        <translation>completato</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the focal length of {} is unknown (no EXIF, none given): it is estimated from the {} control points</source>
        <translation>la focale di {} è sconosciuta (nessun EXIF, nessuna indicata): è stimata dai {} punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM {} reprojected on the fly into the working CRS</source>
        <translation>DSM {} riproiettato al volo nel SR di lavoro</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>captures: {}/{} stacked</source>
        <translation>acquisizioni: {}/{} impilate</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>capture {} left out: {}</source>
        <translation>acquisizione {} esclusa: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky: {} of {} images show sky, hidden from the alignment</source>
        <translation>cielo: {} di {} immagini mostrano il cielo, nascosto all'allineamento</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>one photo ({}): screened on its own, with no set to compare with (only the absolute limits: clipped highlights and shadows, dynamic range); prepared as a set&apos;s photos are</source>
        <translation>una foto ({}): controllata da sola, senza un insieme con cui confrontarla (solo i limiti assoluti: luci e ombre saturate, gamma dinamica); preparata come le foto di un insieme</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>masks: {} polygons ({}, y {}) hide parts of {} of {} images</source>
        <translation>maschere: {} poligoni ({}, y {}) nascondono parti di {} di {} immagini</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>masks: {}/{}</source>
        <translation>maschere: {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>fiducials: {}/{} scans ({}: {} marks)</source>
        <translation>marche fiduciali: {}/{} scansioni ({}: {} marche)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>resampling {}</source>
        <translation>ricampionamento di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>screening: {}/{} images ({})</source>
        <translation>controllo: {}/{} immagini ({})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky: {}</source>
        <translation>cielo: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky mask: {}: {} % of the photo (rows {}–{})</source>
        <translation>maschera del cielo: {}: {} % della foto (righe {}–{})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky mask: {}: none, {}</source>
        <translation>maschera del cielo: {}: nessuna, {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>screened {} images: {} flagged, {} excluded</source>
        <translation>{} immagini controllate: {} segnalate, {} escluse</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>writing the screening record</source>
        <translation>scrittura del registro di controllo</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reading the sparse model</source>
        <translation>lettura del modello sparso</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>report written: {}</source>
        <translation>rapporto scritto: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>report: {}</source>
        <translation>rapporto: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>uncertainty: bundle adjustment covariance</source>
        <translation>incertezza: covarianza della compensazione a stelle proiettive</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{}: block {} of {}</source>
        <translation>{}: blocco {} di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} of {} ({} x {} cells): {}</source>
        <translation>{} di {} ({} x {} celle): {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>contours</source>
        <translation>curve di livello</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM A read</source>
        <translation>DSM A letto</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM B warped onto the grid of DSM A</source>
        <translation>DSM B ricampionato sulla griglia del DSM A</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM difference written</source>
        <translation>differenza dei DSM scritta</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: interpolating under the objects</source>
        <translation>filtro del terreno: interpolazione sotto gli oggetti</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: window {} m</source>
        <translation>filtro del terreno: finestra {} m</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: tile {} of {}</source>
        <translation>filtro del terreno: tassello {} di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: object {} of {}</source>
        <translation>filtro del terreno: oggetto {} di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>relief visualisation: {}</source>
        <translation>visualizzazione del rilievo: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>relief visualisation: {}, tile {} of {}</source>
        <translation>visualizzazione del rilievo: {}, tassello {} di {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>saving the reference {} {}: {}</source>
        <translation>salvataggio del riferimento {} {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reference {} saved to {} ({} % of it has data)</source>
        <translation>riferimento {} salvato in {} ({} % con dati)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reference {} {}: {} x {} m at {} m would exceed {} pixels: saved at {} m</source>
        <translation>riferimento {} {}: {} x {} m a {} m supererebbero {} pixel: salvato a {} m</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>saving the reference {} {}</source>
        <translation>salvataggio del riferimento {} {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the photos are corrected as the orthophoto&apos;s (exposure, vignetting, hot spot)</source>
        <translation>le foto sono corrette come per l'ortofoto (esposizione, vignettatura, hot spot)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} camera(s) lie far outside the block&apos;s dense points and are left out of the DSM&apos;s extent: {}{} (check their alignment)</source>
        <translation>{} fotocamera/e lontane dai punti densi del blocco, escluse dall&apos;estensione del DSM: {}{} (controllarne l&apos;allineamento)</translation>
    </message>
</context>
<context>
    <name>DsmDifferenceAlgorithm</name>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="36"/>
        <source>Earlier DSM</source>
        <translation>DSM precedente</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="36"/>
        <source>Later DSM</source>
        <translation>DSM successivo</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="41"/>
        <source>Difference</source>
        <translation>Differenza</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="42"/>
        <source>Median difference (m)</source>
        <translation>Mediana della differenza (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="43"/>
        <source>Standard deviation of the difference (m)</source>
        <translation>Deviazione standard della differenza (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="44"/>
        <source>Cells compared</source>
        <translation>Celle confrontate</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="45"/>
        <source>Cells changed by more than 1 m</source>
        <translation>Celle cambiate di più di 1 m</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="55"/>
        <source>{} cells compared: median {:.3f} m, mean {:.3f} m, std {:.3f} m, 5-95 % {:.3f} .. {:.3f} m; {} cells changed by more than {:g} m</source>
        <translation>{} celle confrontate: mediana {:.3f} m, media {:.3f} m, dev. std. {:.3f} m, 5-95 % {:.3f} .. {:.3f} m; {} celle cambiate di più di {:g} m</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM difference</source>
        <translation>Differenza tra DSM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>The later DSM minus the earlier one, on the earlier one&apos;s grid, shows what changed between two epochs of a site (the later DSM is warped there with GDAL, bilinear, from any CRS). A cell is nodata where either DSM has none. The log gives the cells compared, the median, mean and standard deviation of the difference, its 5th and 95th percentiles and the cells that changed by more than 1 m; a median near 0 says the two epochs are registered on each other.

Earlier DSM: the DSM the difference is measured from (its grid is the output&apos;s).
Later DSM: the DSM of the other epoch (e.g. a block registered to the earlier one with Automatic control).
Difference: where to write the float32 Cloud-Optimized GeoTIFF of later minus earlier (metres).</source>
        <translation>Il DSM successivo meno quello precedente, sulla griglia del precedente, mostra cosa è cambiato tra due epoche di un sito (il DSM successivo vi viene ricampionato con GDAL, bilineare, da qualsiasi SR). Una cella è nodata dove uno dei due DSM non ha dati. Il registro riporta le celle confrontate, mediana, media e deviazione standard della differenza, il 5° e il 95° percentile e le celle cambiate di più di 1 m; una mediana vicina a 0 dice che le due epoche sono registrate l'una sull'altra.

DSM precedente: il DSM da cui si misura la differenza (la sua griglia è quella dell'output).
DSM successivo: il DSM dell'altra epoca (ad es. un blocco registrato sul precedente con il controllo automatico).
Differenza: dove scrivere il Cloud-Optimized GeoTIFF float32 di successivo meno precedente (metri).</translation>
    </message>
</context>
<context>
    <name>FindTargetsAlgorithm</name>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Aligned workspace</source>
        <translation>Area di lavoro allineata</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Targets (surveyed coordinates)</source>
        <translation>Target (coordinate rilevate)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Target kind</source>
        <translation>Tipo di target</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Target size (m, 0: unknown)</source>
        <translation>Dimensione dei target (m, 0: sconosciuta)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="71"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="72"/>
        <source>Targets found (for review)</source>
        <translation>Target trovati (da verificare)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="73"/>
        <source>Targets found</source>
        <translation>Target trovati</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="74"/>
        <source>Observations found</source>
        <translation>Misure trovate</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="91"/>
        <source>{} of {} targets found, {} observations; {} candidate marks, {} tied across photos</source>
        <translation>{} di {} target trovati, {} misure; {} segni candidati, {} collegati tra le foto</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Find targets</source>
        <translation>Trova i target</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Finds the surveyed ground targets on the photos of an aligned block and writes their observations, sub-pixel, as a gcp_list.txt that Georeference reads: no clicks. No GPS or first click is needed: marks are detected on every photo, tied across photos by triangulation in the block, and the triangulated marks are matched to the surveyed coordinates by their shape (a similarity found from triplets; scale and mirror searched; the photos&apos; EXIF GPS, where they have it, narrows the search); then every named target is projected into every photo and the mark there joins it. Coded targets (ArUco, AprilTag) carry their names: a target named by its code or ending in it (12, T12, aruco_12).

Aligned workspace: the block (its photos must still be where the alignment found them).
Targets: the surveyed coordinates, a CSV &apos;name,x,y,z[,sigma_xy,sigma_z]&apos; (CRS as a &apos;# crs: EPSG:xxxx&apos; line or the CRS parameter) or an OpenDroneMap gcp_list.txt whose pixel columns may be absent (&apos;x y z name&apos;) or partial: where present they are clicks that name the mark they fall on (checked against the constellation; a click on another target&apos;s mark is reported and left out).
CRS: the coordinates&apos; CRS where the file names none.
Target kind: auto (crosses, checkerboards, circles and ArUco 4x4 markers), one kind, or an ArUco / AprilTag dictionary.
Target size: the target&apos;s side or diameter in metres (0: unknown); a mark whose size on the ground (its pixels at its distance, through the scale the constellation gives) differs from it by more than a factor 2 is left out.
A target that a photo shows only in part, or covered, is left out rather than guessed; a mark that does not fit the surveyed constellation, or a naming that another fits almost as well, is reported in the log, never assigned.
Outputs: the observations file (default georef/targets/gcp_list.txt in the workspace), a layer of the targets with what was found (georef/targets/targets.gpkg: observations, fit, residual) for review, the numbers of targets and observations found; georef/targets/targets.json lists every observation with its quality.</source>
        <translation>Trova i target a terra rilevati nelle foto di un blocco allineato e ne scrive le misure, al sub-pixel, in un gcp_list.txt che Georeferenzia legge: nessun clic. Non servono né GPS né un primo clic: i segni vengono rilevati in ogni foto, collegati tra le foto per triangolazione nel blocco, e i segni triangolati vengono abbinati alle coordinate rilevate in base alla loro forma (una similitudine trovata da terne; scala e specchiatura cercate; il GPS EXIF delle foto, dove c'è, restringe la ricerca); poi ogni target nominato viene proiettato in ogni foto e il segno lì presente gli si unisce. I target codificati (ArUco, AprilTag) portano il proprio nome: un target chiamato con il suo codice o che termina con esso (12, T12, aruco_12).

Area di lavoro allineata: il blocco (le sue foto devono essere ancora dove l'allineamento le ha trovate).
Target: le coordinate rilevate, un CSV 'name,x,y,z[,sigma_xy,sigma_z]' (SR come riga '# crs: EPSG:xxxx' o nel parametro SR) o un gcp_list.txt di OpenDroneMap le cui colonne dei pixel possono mancare ('x y z name') o essere parziali: dove presenti sono clic che danno il nome al segno su cui cadono (verificati rispetto alla costellazione; un clic sul segno di un altro target viene segnalato ed escluso).
SR: l'SR delle coordinate se il file non ne indica uno.
Tipo di target: automatico (croci, scacchiere, cerchi e marker ArUco 4x4), un solo tipo, o un dizionario ArUco / AprilTag.
Dimensione dei target: lato o diametro del target in metri (0: sconosciuta); un segno la cui dimensione a terra (i suoi pixel alla sua distanza, tramite la scala data dalla costellazione) ne differisce di più di un fattore 2 viene escluso.
Un target che una foto mostra solo in parte, o coperto, viene escluso invece che indovinato; un segno che non si adatta alla costellazione rilevata, o un'assegnazione di nomi che un'altra soddisfa quasi altrettanto bene, viene segnalato nel log, mai assegnato.
Output: il file delle misure (predefinito georef/targets/gcp_list.txt nell'area di lavoro), un layer dei target con quanto trovato (georef/targets/targets.gpkg: misure, adattamento, residuo) da verificare, il numero di target e di misure trovati; georef/targets/targets.json elenca ogni misura con la sua qualità.</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>CRS (where the file names none)</source>
        <translation>SR (se il file non ne indica uno)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="68"/>
        <source>Observations file</source>
        <translation>File delle misure</translation>
    </message>
</context>
<context>
    <name>FolderDialog</name>
    <message>
        <location filename="../ui/folder_dialog.py" line="47"/>
        <source>The folder {} cannot be made: {}</source>
        <translation>Impossibile creare la cartella {}: {}</translation>
    </message>
</context>
<context>
    <name>GcpDock</name>
    <message>
        <location filename="../ui/gcp_dock.py" line="221"/>
        <source>Report</source>
        <translation>Rapporto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="222"/>
        <source>Open the workspace&apos;s accuracy report (report.html, made by Run pipeline or Accuracy report) in the web browser</source>
        <translation>Apri il rapporto di accuratezza dello spazio di lavoro (report.html, creato da Run pipeline o Accuracy report) nel browser web</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="601"/>
        <source>The workspace has no accuracy report yet: run Accuracy report (or Run pipeline)</source>
        <translation>Lo spazio di lavoro non ha ancora un rapporto di accuratezza: eseguire Accuracy report (o Run pipeline)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="396"/>
        <source>No web browser opened {}</source>
        <translation>Nessun browser web ha aperto {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="398"/>
        <source>Accuracy report: {}</source>
        <translation>Rapporto di accuratezza: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="82"/>
        <source>ArchaeoOrtho ground control</source>
        <translation>ArchaeoOrtho punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="99"/>
        <source>ArchaeoOrtho photos</source>
        <translation>ArchaeoOrtho foto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="161"/>
        <source>Workspace:</source>
        <translation>Area di lavoro:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="429"/>
        <source>none open</source>
        <translation>nessuna aperta</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="168"/>
        <source>Open a workspace folder (made by Align images)</source>
        <translation>Apri una cartella dell'area di lavoro (creata da 'Allinea immagini')</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="170"/>
        <source>Choose a folder of photos and a workspace folder, and align the photos</source>
        <translation>Scegli una cartella di foto e una cartella dell'area di lavoro e allinea le foto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="177"/>
        <source>Heights (Z) from:</source>
        <translation>Quote (Z) da:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="182"/>
        <source>A DSM or DTM raster layer (e.g. an ALS DSM): a point picked on the map takes its height from it (bilinear). Empty: type Z by hand. Only height rasters are listed (not orthophotos, hillshades or web maps).</source>
        <translation>Un layer raster DSM o DTM (ad es. un DSM ALS): un punto misurato sulla mappa ne prende la quota (bilineare). Vuoto: inserire Z a mano. Sono elencati solo raster di quote (non ortofoto, ombreggiature o mappe web).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="67"/>
        <source>Add</source>
        <translation>Aggiungi</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="198"/>
        <source>Add a ground point</source>
        <translation>Aggiungi un punto d'appoggio</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="199"/>
        <source>Remove</source>
        <translation>Rimuovi</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="200"/>
        <source>Remove the selected ground point and its observations</source>
        <translation>Rimuovi il punto d'appoggio selezionato e le sue misure</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="195"/>
        <source>Pick on map</source>
        <translation>Misura sulla mappa</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="203"/>
        <source>Click on the map canvas to set X and Y of the selected point (Z from the heights layer)</source>
        <translation>Fai clic sulla mappa per impostare X e Y del punto selezionato (Z dal layer delle quote)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="64"/>
        <source>Import</source>
        <translation>Importa</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="212"/>
        <source>Export</source>
        <translation>Esporta</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="230"/>
        <source>Undo</source>
        <translation>Annulla</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="231"/>
        <source>Redo</source>
        <translation>Ripeti</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="241"/>
        <source>Undo: {}</source>
        <translation>Annulla: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="243"/>
        <source>Redo: {}</source>
        <translation>Ripeti: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="219"/>
        <source>Load results</source>
        <translation>Carica risultati</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="220"/>
        <source>Add the workspace&apos;s products to the map as styled layers</source>
        <translation>Aggiungi i prodotti dell'area di lavoro alla mappa come layer con stile</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="277"/>
        <source>Residual tolerance:</source>
        <translation>Tolleranza dei residui:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="283"/>
        <source>Residuals up to this are green, up to 3 times yellow, beyond red</source>
        <translation>Residui fino a questo valore sono verdi, fino al triplo gialli, oltre rossi</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="292"/>
        <source>Refine camera calibration</source>
        <translation>Affina la calibrazione della camera</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="293"/>
        <source>Let the adjustment refine focal length, principal point and distortion</source>
        <translation>Lascia che la compensazione affini focale, punto principale e distorsione</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="300"/>
        <source>Georeference</source>
        <translation>Georeferenzia</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="301"/>
        <source>Run the adjustment with these points (in the background)</source>
        <translation>Esegui la compensazione con questi punti (in background)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="302"/>
        <source>Cancel</source>
        <translation>Interrompi</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="355"/>
        <source>ArchaeoOrtho</source>
        <translation>ArchaeoOrtho</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="362"/>
        <source>Open an ArchaeoOrtho workspace</source>
        <translation>Apri un'area di lavoro ArchaeoOrtho</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="454"/>
        <source>{} photos; the block is not aligned yet: run Align images (or &apos;New from photos&apos;) to get predicted positions</source>
        <translation>{} foto; il blocco non è ancora allineato: esegui 'Allinea immagini' (o 'Nuova dalle foto') per avere le posizioni previste</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="457"/>
        <source>{} photos, {} ground points. {}</source>
        <translation>{} foto, {} punti d'appoggio. {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="283"/>
        <source>no predicted positions: {}</source>
        <translation>nessuna posizione prevista: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="66"/>
        <source>Predicted positions from the georeferenced block.</source>
        <translation>Posizioni previste dal blocco georeferenziato.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="66"/>
        <source>Predicted positions once a point is placed in 2 photos, and for every point once 3 points are placed.</source>
        <translation>Posizioni previste quando un punto è misurato in 2 foto, e per tutti i punti quando ne sono misurati 3.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="185"/>
        <source>Folder of photos</source>
        <translation>Cartella delle foto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="191"/>
        <source>Workspace folder (new or existing)</source>
        <translation>Cartella dell'area di lavoro (nuova o esistente)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="205"/>
        <source>Aligned {} of {} photos, mean reprojection error {:.2f} px</source>
        <translation>Allineate {} di {} foto, errore medio di riproiezione {:.2f} px</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="212"/>
        <source>ArchaeoOrtho: align photos</source>
        <translation>ArchaeoOrtho: allinea le foto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="612"/>
        <source>CRS: {}</source>
        <translation>SR: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="119"/>
        <source>Click on the map at the selected point&apos;s position (Esc to stop)</source>
        <translation>Fai clic sulla mappa nella posizione del punto selezionato (Esc per terminare)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="183"/>
        <source>{}: X {:.3f}, Y {:.3f}, Z {:.3f} (from {})</source>
        <translation>{}: X {:.3f}, Y {:.3f}, Z {:.3f} (da {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="186"/>
        <source>{}: X {:.3f}, Y {:.3f}. No height at this place in {}: Z left as it was</source>
        <translation>{}: X {:.3f}, Y {:.3f}. Nessuna quota in questo punto in {}: Z invariata</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="189"/>
        <source>{}: X {:.3f}, Y {:.3f}</source>
        <translation>{}: X {:.3f}, Y {:.3f}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="395"/>
        <source>{:.1f} px</source>
        <translation>{:.1f} px</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="397"/>
        <source>predicted</source>
        <translation>prevista</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="420"/>
        <source>Select or add a ground point in the table, then click on it in the photo.</source>
        <translation>Seleziona o aggiungi un punto d'appoggio nella tabella, poi fai clic su di esso nella foto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="427"/>
        <source>from the point&apos;s other observations</source>
        <translation>dalle altre misure del punto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="428"/>
        <source>from the georeferenced block</source>
        <translation>dal blocco georeferenziato</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="429"/>
        <source>from the points already placed (similarity fit)</source>
        <translation>dai punti già misurati (trasformazione di similitudine)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="440"/>
        <source>Placed at x {:.2f}, y {:.2f}. Click to move it, drag it, or press Delete to remove it.</source>
        <translation>Misurato in x {:.2f}, y {:.2f}. Fai clic per spostarlo, trascinalo o premi Canc per rimuoverlo.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="443"/>
        <source>Predicted {}. Press Enter to accept it and go on (Space: accept), drag it, or click where the point really is.</source>
        <translation>Previsto {}. Premi Invio per accettarlo e proseguire (Spazio: accetta), trascinalo o fai clic dove si trova davvero il punto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="455"/>
        <source>Click where {} is in this photo.</source>
        <translation>Fai clic dove si trova {} in questa foto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="475"/>
        <source>Select or add a ground point first</source>
        <translation>Seleziona o aggiungi prima un punto d'appoggio</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="522"/>
        <source>{}: every photo predicted to see it has an observation</source>
        <translation>{}: ogni foto in cui è previsto ha una misura</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="130"/>
        <source>Import ground control</source>
        <translation>Importa punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="32"/>
        <source>Ground control (*.txt *.csv);;All files (*)</source>
        <translation>Punti d'appoggio (*.txt *.csv);;Tutti i file (*)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="60"/>
        <source>Replace the current points, or add the imported ones to them (same names are updated)?</source>
        <translation>Sostituire i punti attuali o aggiungere quelli importati (quelli con lo stesso nome vengono aggiornati)?</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="64"/>
        <source>Replace</source>
        <translation>Sostituisci</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="106"/>
        <source>import {}</source>
        <translation>importa {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="107"/>
        <source>warnings</source>
        <translation>avvisi</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="114"/>
        <source>Imported {} points and {} observations from {}</source>
        <translation>Importati {} punti e {} misure da {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="127"/>
        <source>No point layer in the project</source>
        <translation>Nessun layer di punti nel progetto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="130"/>
        <source>Point layer (one feature per observation: name, image, px, py)</source>
        <translation>Layer di punti (un elemento per misura: name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="145"/>
        <source>Layer {} lacks the field &apos;{}&apos; (needs name, image, px, py)</source>
        <translation>Al layer {} manca il campo '{}' (servono name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="172"/>
        <source>OpenDroneMap gcp_list (*.txt)</source>
        <translation>OpenDroneMap gcp_list (*.txt)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="172"/>
        <source>CSV points + observations (*.csv)</source>
        <translation>Punti CSV + misure (*.csv)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="173"/>
        <source>Export ground control</source>
        <translation>Esporta punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="184"/>
        <source>The points have no CRS yet: pick one on the map or import a file first</source>
        <translation>I punti non hanno ancora un SR: misurane uno sulla mappa o importa prima un file</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="193"/>
        <source>Exported {} points to {}</source>
        <translation>Esportati {} punti in {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="193"/>
        <source> ({} without coordinates left out)</source>
        <translation> ({} senza coordinate esclusi)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="198"/>
        <source>Export ground control as a layer</source>
        <translation>Esporta i punti d'appoggio come layer</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="198"/>
        <source>GeoPackage (*.gpkg)</source>
        <translation>GeoPackage (*.gpkg)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="231"/>
        <source>Cannot write {}: {}</source>
        <translation>Impossibile scrivere {}: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="234"/>
        <source>Exported {} observations to {}</source>
        <translation>Esportate {} misure in {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="234"/>
        <source> (points without observations left out: {})</source>
        <translation> (punti senza misure esclusi: {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="238"/>
        <source>GCP observations</source>
        <translation>Misure dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="240"/>
        <source>Cannot add {} to the project</source>
        <translation>Impossibile aggiungere {} al progetto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="224"/>
        <source>A task of this dock is still running</source>
        <translation>Un'operazione di questo pannello è ancora in corso</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="247"/>
        <source>Cancelled</source>
        <translation>Interrotto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="263"/>
        <source>The block is not aligned yet: run Align images first</source>
        <translation>Il blocco non è ancora allineato: esegui prima 'Allinea immagini'</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="269"/>
        <source>The adjustment needs at least 3 control points with coordinates and observations; there are {}</source>
        <translation>La compensazione richiede almeno 3 punti d'appoggio con coordinate e misure; ce ne sono {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="287"/>
        <source>Outliers left out: {}</source>
        <translation>Valori anomali esclusi: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="288"/>
        <source>Georeferenced in {}.</source>
        <translation>Georeferenziato in {}.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="292"/>
        <source>ArchaeoOrtho: georeference</source>
        <translation>ArchaeoOrtho: georeferenzia</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="301"/>
        <source>Not georeferenced yet.</source>
        <translation>Non ancora georeferenziato.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="303"/>
        <source>Control: RMSE XY {} m, Z {} m (n = {})</source>
        <translation>Appoggio: RMSE XY {} m, Z {} m (n = {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="306"/>
        <source>Check: RMSE XY {} m, Z {} m (n = {})</source>
        <translation>Controllo: RMSE XY {} m, Z {} m (n = {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="309"/>
        <source>heights are placeholders: no vertical accuracy</source>
        <translation>le quote sono segnaposto: nessuna accuratezza verticale</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="311"/>
        <source>tie points {} px</source>
        <translation>punti di legame {} px</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="313"/>
        <source>edited since: re-run to update</source>
        <translation>modificato da allora: riesegui per aggiornare</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="430"/>
        <source>by matching its look in another photo</source>
        <translation>confrontandone l'aspetto in un'altra foto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="434"/>
        <source>(correlation {:.2f}, {:.0f} px from the geometric prediction)</source>
        <translation>(correlazione {:.2f}, {:.0f} px dalla previsione geometrica)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="167"/>
        <source>Open…</source>
        <translation>Apri…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="169"/>
        <source>New from photos…</source>
        <translation>Nuova dalle foto…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="206"/>
        <source>From file (gcp_list.txt, CSV)…</source>
        <translation>Da file (gcp_list.txt, CSV)…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="207"/>
        <source>From a point layer…</source>
        <translation>Da un layer di punti…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="210"/>
        <source>To file (gcp_list.txt, CSV)…</source>
        <translation>Su file (gcp_list.txt, CSV)…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="211"/>
        <source>To a GeoPackage layer…</source>
        <translation>Su un layer GeoPackage…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="255"/>
        <source>Cancelling…</source>
        <translation>Interruzione…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="295"/>
        <source>Georeferencing with {} control points…</source>
        <translation>Georeferenziazione con {} punti d'appoggio…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="60"/>
        <source>How were the pixel coordinates measured?</source>
        <translation>Come sono state misurate le coordinate pixel?</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="71"/>
        <source>Coordinates measured on upright photos ({} photos are stored turned: EXIF orientation); leave unticked for the stored pixel grid (COLMAP&apos;s, OpenDroneMap&apos;s)</source>
        <translation>Coordinate misurate sulle foto raddrizzate ({} foto sono salvate ruotate: orientamento EXIF); lasciare deselezionato per la griglia di pixel salvata (quella di COLMAP e OpenDroneMap)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="75"/>
        <source>your setting</source>
        <translation>la tua impostazione</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="78"/>
        <source>default: 3 × GSD of the georeferenced block (GSD {:.3f} m)</source>
        <translation>predefinito: 3 × GSD del blocco georeferenziato (GSD {:.3f} m)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="79"/>
        <source>default</source>
        <translation>predefinito</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="86"/>
        <source>Residuals up to this are green, up to 3 times yellow, beyond red. Now: {}</source>
        <translation>I residui fino a questo valore sono verdi, fino al triplo gialli, oltre rossi. Ora: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="96"/>
        <source>Diagnosis of the adjustment:</source>
        <translation>Diagnosi della compensazione:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="174"/>
        <source>Moved {:.2f} m (Undo: Ctrl+Z).</source>
        <translation>Spostato di {:.2f} m (Annulla: Ctrl+Z).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="397"/>
        <source>near the edge</source>
        <translation>vicino al bordo</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="446"/>
        <source>{} is predicted where it cannot be placed: {}. Click where the point is if you see it, or press Enter for the next photo.</source>
        <translation>{} è previsto dove non può essere posizionato: {}. Fai clic sul punto se lo vedi, o premi Invio per la foto successiva.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="452"/>
        <source>Click where {} is in this photo, or use Pick on map (or type X, Y, Z in the table) to have it predicted in the photos.</source>
        <translation>Fai clic su {} in questa foto, oppure usa Misura sulla mappa (o scrivi X, Y, Z nella tabella) per farlo prevedere nelle foto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="465"/>
        <source>{}: the workspace has no photos to place it in.</source>
        <translation>{}: l'area di lavoro non ha foto in cui posizionarlo.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="467"/>
        <source>{} is selected: use Pick on map or type X, Y, Z in the table, or choose a photo in the strip below and click on the point.</source>
        <translation>{} è selezionato: usa Misura sulla mappa o scrivi X, Y, Z nella tabella, oppure scegli una foto nella striscia sotto e fai clic sul punto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="469"/>
        <source>{} is selected: choose a photo in the strip below and click on the point.</source>
        <translation>{} è selezionato: scegli una foto nella striscia sotto e fai clic sul punto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="238"/>
        <source>Undo (Ctrl+Z)</source>
        <translation>Annulla (Ctrl+Z)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="238"/>
        <source>Redo (Ctrl+Shift+Z)</source>
        <translation>Ripeti (Ctrl+Maiusc+Z)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="475"/>
        <source>Aligned {} of {} photos, mean reprojection error {:.2f} px.</source>
        <translation>Allineate {} di {} foto, errore medio di riproiezione {:.2f} px.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="480"/>
        <source>Not aligned ({}): {}</source>
        <translation>Non allineate ({}): {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="481"/>
        <source>(marked in the photo strip; hover for the reason)</source>
        <translation>(segnate nella striscia delle foto; il motivo è nel suggerimento)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="510"/>
        <source>✗ not aligned</source>
        <translation>✗ non allineata</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="511"/>
        <source>{}: not aligned: {}</source>
        <translation>{}: non allineata: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="208"/>
        <source>Not aligned: {}</source>
        <translation>Non allineate: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="141"/>
        <source>pick on map</source>
        <translation>misura sulla mappa</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="432"/>
        <source>(no Z yet: at the height of the block&apos;s tie points)</source>
        <translation>(ancora nessuna Z: all'altezza dei punti di legame del blocco)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="166"/>
        <source>{} not moved</source>
        <translation>{} non spostato</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="195"/>
        <source>{} is placed in {} photos. Move it {:.2f} m to the picked position, or add a new point there?</source>
        <translation>{} è posizionato in {} foto. Spostarlo di {:.2f} m nella posizione misurata, o aggiungere lì un nuovo punto?</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="199"/>
        <source>Move {}</source>
        <translation>Sposta {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="200"/>
        <source>New point</source>
        <translation>Nuovo punto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="157"/>
        <source>ArchaeoOrtho: refine {} in {}</source>
        <translation>ArchaeoOrtho: affina {} in {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="327"/>
        <source>Results loaded</source>
        <translation>Risultati caricati</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="334"/>
        <source>ArchaeoOrtho: load results</source>
        <translation>ArchaeoOrtho: carica i risultati</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="336"/>
        <source>Loading the results…</source>
        <translation>Caricamento dei risultati…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="111"/>
        <source>ArchaeoOrtho: open workspace</source>
        <translation>ArchaeoOrtho: apri l'area di lavoro</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="113"/>
        <source>Opening {}…</source>
        <translation>Apertura di {}…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="49"/>
        <source>Automatic control from a reference orthophoto</source>
        <translation>Controllo automatico da ortofoto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="52"/>
        <source>Georeference with no hand-picked GCP: the block is matched to a reference orthophoto and takes its heights from a reference DSM. The points of the table become check points.</source>
        <translation>Georeferenziare senza punti d'appoggio scelti a mano: il blocco viene abbinato a un'ortofoto di riferimento e prende le quote da un DSM di riferimento. I punti della tabella diventano punti di controllo.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="58"/>
        <source>A reference orthophoto: a raster file, or a WMS / XYZ layer (saved for the block&apos;s extent, from the photos&apos; GPS or the map extent)</source>
        <translation>Un'ortofoto di riferimento: un file raster, o un layer WMS / XYZ (salvato per l'estensione del blocco, dal GPS delle foto o dall'estensione della mappa)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="58"/>
        <source>A reference DSM or DTM (heights in metres): a raster file or a WCS layer. Only height rasters are listed: not orthophotos, hillshades, web maps or this workspace&apos;s own products</source>
        <translation>Un DSM o DTM di riferimento (quote in metri): un file raster o un layer WCS. Sono elencati solo raster di quote: non ortofoto, ombreggiature, mappe web o prodotti di questo spazio di lavoro</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="69"/>
        <source>Reference orthophoto:</source>
        <translation>Ortofoto di riferimento:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="70"/>
        <source>Reference DSM:</source>
        <translation>DSM di riferimento:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="116"/>
        <source>Georeference from the reference orthophoto and DSM (in the background)</source>
        <translation>Georeferenzia dall'ortofoto e dal DSM di riferimento (in background)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="137"/>
        <source>Automatic control: choose a reference orthophoto and a reference DSM layer</source>
        <translation>Controllo automatico: scegliere un'ortofoto di riferimento e un layer DSM di riferimento</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="158"/>
        <source>Automatic control: {} automatic GCPs kept of {} matches; georeferenced in {}.</source>
        <translation>Controllo automatico: {} GCP automatici mantenuti su {} corrispondenze; georeferenziato in {}.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="161"/>
        <source>Check points: RMSE XY {:.3f} m, Z {:.3f} m (n = {}).</source>
        <translation>Punti di controllo: RMSE XY {:.3f} m, Z {:.3f} m (n = {}).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="172"/>
        <source>ArchaeoOrtho: automatic control</source>
        <translation>ArchaeoOrtho: controllo automatico</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="176"/>
        <source>Automatic control against {} and {}…</source>
        <translation>Controllo automatico rispetto a {} e {}…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="188"/>
        <source>Automatic GCPs (residuals)</source>
        <translation>GCP automatici (residui)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="66"/>
        <source>found by Find targets ({}), quality {:.2f}</source>
        <translation>trovato da Trova i target ({}), qualità {:.2f}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="69"/>
        <source>, {:.2f} px from the other photos&apos; rays</source>
        <translation>, a {:.2f} px dai raggi delle altre foto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="80"/>
        <source>Find targets</source>
        <translation>Trova i target</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="86"/>
        <source>Surveyed coordinates (*.csv *.txt);;All files (*)</source>
        <translation>Coordinate rilevate (*.csv *.txt);;Tutti i file (*)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="87"/>
        <source>A CSV name,x,y,z[,sigma_xy,sigma_z] or an ODM gcp_list.txt (its pixel columns may be absent)</source>
        <translation>Un CSV name,x,y,z[,sigma_xy,sigma_z] o un gcp_list.txt di ODM (le colonne dei pixel possono mancare)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="89"/>
        <source>Surveyed coordinates:</source>
        <translation>Coordinate rilevate:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="93"/>
        <source>auto (crosses, checkerboards, circles, ArUco 4x4)</source>
        <translation>automatico (croci, scacchiere, cerchi, ArUco 4x4)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="95"/>
        <source>Target kind:</source>
        <translation>Tipo di target:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="100"/>
        <source>unknown</source>
        <translation>sconosciuta</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="101"/>
        <source>The target&apos;s side or diameter: marks of another size are left out</source>
        <translation>Lato o diametro del target: i segni di altra dimensione vengono esclusi</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="102"/>
        <source>Target size:</source>
        <translation>Dimensione dei target:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="104"/>
        <source>A file that names no CRS is read in {}.</source>
        <translation>Un file che non indica un SR viene letto in {}.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="104"/>
        <source>The file must name its CRS (the table and the workspace have none).</source>
        <translation>Il file deve indicare il suo SR (la tabella e l'area di lavoro non ne hanno).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="157"/>
        <source>Find targets on the photos…</source>
        <translation>Trova i target nelle foto…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="158"/>
        <source>Find the surveyed targets on the aligned photos (in the background): their observations fill the table, marked as found until you confirm them (Space or Enter) or reject them (Delete or R)</source>
        <translation>Trova i target rilevati nelle foto allineate (in background): le loro misure riempiono la tabella, segnate come trovate finché non le confermi (Spazio o Invio) o le scarti (Canc o R)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="209"/>
        <source>ArchaeoOrtho: find targets</source>
        <translation>ArchaeoOrtho: trova i target</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="211"/>
        <source>Looking for the targets of {} on the photos…</source>
        <translation>Ricerca dei target di {} nelle foto…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="237"/>
        <source>find targets</source>
        <translation>trova i target</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="239"/>
        <source>Find targets: {} of {} targets found, {} observations, in {:.0f} s.</source>
        <translation>Trova i target: {} di {} target trovati, {} misure, in {:.0f} s.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="244"/>
        <source>not found: {}</source>
        <translation>non trovati: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="316"/>
        <source>Every found observation is confirmed or rejected</source>
        <translation>Ogni misura trovata è confermata o scartata</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="356"/>
        <source>{} observations found by Find targets, not confirmed: {}</source>
        <translation>{} misure trovate da Trova i target, non confermate: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="367"/>
        <source>{} found observations are not confirmed yet: they are used as they are (reject the wrong ones first)</source>
        <translation>{} misure trovate non sono ancora confermate: vengono usate così come sono (scarta prima quelle sbagliate)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="216"/>
        <source>{} (automatic)</source>
        <translation>{} (automatico)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="218"/>
        <source>Automatic GCP: measured by the automatic control (matched against the reference orthophoto)</source>
        <translation>GCP automatico: misurato dal controllo automatico (confrontato con l'ortofoto di riferimento)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="221"/>
        <source>&lt;b&gt;{}&lt;/b&gt; (automatic GCP) — {}</source>
        <translation>&lt;b&gt;{}&lt;/b&gt; (GCP automatico) — {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="222"/>
        <source>{} is an automatic GCP: found by the automatic control at x {:.2f}, y {:.2f} in this photo (measured in {} photos), not a prediction to place. Drag it to correct it, or press Delete to remove it from this photo.</source>
        <translation>{} è un GCP automatico: trovato dal controllo automatico a x {:.2f}, y {:.2f} in questa foto (misurato in {} foto), non una previsione da collocare. Trascinalo per correggerlo o premi Canc per toglierlo da questa foto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="249"/>
        <source>Space or Enter: confirm the found observation shown; Delete or R: reject it (the keys work in the table, which has the keyboard focus now, and in the photo view). Georeference uses the found observations that are not rejected, confirmed or not.</source>
        <translation>Spazio o Invio: conferma l'osservazione trovata mostrata; Canc o R: la scarta (i tasti funzionano nella tabella, che ora ha il fuoco della tastiera, e nella vista della foto). Georeferenzia usa le osservazioni trovate non scartate, confermate o no.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="332"/>
        <source>Found by Find targets, not confirmed: Space or Enter confirms it, Delete or R rejects it (then the next one); the keys work in the table and in this photo view.</source>
        <translation>Trovata da Trova i target, non confermata: Spazio o Invio la conferma, Canc o R la scarta (poi la successiva); i tasti funzionano nella tabella e in questa vista della foto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="121"/>
        <source>{} has new results: open it once this dock&apos;s task has ended</source>
        <translation>{} ha nuovi risultati: aprila al termine dell'attività di questo pannello</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="218"/>
        <source>Aligning the photos of {} into {}…</source>
        <translation>Allineamento delle foto di {} in {}…</translation>
    </message>
</context>
<context>
    <name>GcpStore</name>
    <message>
        <location filename="../ui/store.py" line="316"/>
        <source>a point named {} exists already</source>
        <translation>esiste già un punto chiamato {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="304"/>
        <source>add point {}</source>
        <translation>aggiungi il punto {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="311"/>
        <source>remove point {}</source>
        <translation>rimuovi il punto {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="329"/>
        <source>set {} of {}</source>
        <translation>imposta {} di {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="389"/>
        <source>place {} in {}</source>
        <translation>misura {} in {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="397"/>
        <source>remove {} from {}</source>
        <translation>rimuovi {} da {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="538"/>
        <source>set CRS</source>
        <translation>imposta il SR</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="357"/>
        <source>no position</source>
        <translation>nessuna posizione</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="362"/>
        <source>({:.0f}, {:.0f}) is outside the photo {} ({} × {} px)</source>
        <translation>({:.0f}, {:.0f}) è fuori dalla foto {} ({} × {} px)</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="369"/>
        <source>({:.0f}, {:.0f}) is inside the mask of {}</source>
        <translation>({:.0f}, {:.0f}) è dentro la maschera di {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="377"/>
        <source>{} not placed: {}</source>
        <translation>{} non posizionato: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="429"/>
        <source>{} points replaced by {} from the file</source>
        <translation>{} punti sostituiti da {} dal file</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="463"/>
        <source>added {} points: {}</source>
        <translation>aggiunti {} punti: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="465"/>
        <source>coordinates updated from the file: {}</source>
        <translation>coordinate aggiornate dal file: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="467"/>
        <source>role set by the file: {}</source>
        <translation>ruolo impostato dal file: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="469"/>
        <source>role kept (the file gives none): {}</source>
        <translation>ruolo mantenuto (il file non ne indica): {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="471"/>
        <source>σ set by the file: {}</source>
        <translation>σ impostata dal file: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="473"/>
        <source>{} observations added</source>
        <translation>{} misure aggiunte</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="475"/>
        <source>placed observations kept (the file has others): {}</source>
        <translation>misure posizionate mantenute (il file ne ha altre): {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="477"/>
        <source>nothing changed</source>
        <translation>nulla è cambiato</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="486"/>
        <source>observations placed by hand kept (found ones not used there): {}</source>
        <translation>misure posizionate a mano mantenute (quelle trovate lì non usate): {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="526"/>
        <source>confirm {} in {}</source>
        <translation>conferma {} in {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="535"/>
        <source>reject {} in {}</source>
        <translation>scarta {} in {}</translation>
    </message>
</context>
<context>
    <name>GcpTableModel</name>
    <message>
        <location filename="../ui/gcp_table.py" line="37"/>
        <source>Name</source>
        <translation>Nome</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="37"/>
        <source>X</source>
        <translation>X</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="37"/>
        <source>Y</source>
        <translation>Y</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="37"/>
        <source>Z</source>
        <translation>Z</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="38"/>
        <source>Role</source>
        <translation>Ruolo</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="38"/>
        <source>Obs.</source>
        <translation>Mis.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="38"/>
        <source>dXY (m)</source>
        <translation>dXY (m)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="38"/>
        <source>dZ (m)</source>
        <translation>dZ (m)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="38"/>
        <source>px</source>
        <translation>px</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="41"/>
        <source>check</source>
        <translation>controllo</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="41"/>
        <source>control</source>
        <translation>appoggio</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="53"/>
        <source>Horizontal residual after the adjustment (estimated from the photos minus given)</source>
        <translation>Residuo planimetrico dopo la compensazione (stimato dalle foto meno dato)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="54"/>
        <source>Vertical residual after the adjustment</source>
        <translation>Residuo altimetrico dopo la compensazione</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="55"/>
        <source>Mean reprojection error of the point&apos;s observations (pixels)</source>
        <translation>Errore medio di riproiezione delle misure del punto (pixel)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="56"/>
        <source>Number of photos the point is placed in</source>
        <translation>Numero di foto in cui il punto è misurato</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="69"/>
        <source>rejected as an outlier</source>
        <translation>scartato come valore anomalo</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="71"/>
        <source>not triangulated (fewer than 2 usable observations)</source>
        <translation>non triangolato (meno di 2 misure utilizzabili)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="77"/>
        <source>within the tolerance</source>
        <translation>entro la tolleranza</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="79"/>
        <source>up to 3 times the tolerance</source>
        <translation>fino al triplo della tolleranza</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="80"/>
        <source>more than 3 times the tolerance</source>
        <translation>oltre il triplo della tolleranza</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="131"/>
        <source>edited since the last adjustment: run Georeference to update</source>
        <translation>modificato dopo l'ultima compensazione: esegui 'Georeferenzia' per aggiornare</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="37"/>
        <source>σ XY</source>
        <translation>σ XY</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="37"/>
        <source>σ Z</source>
        <translation>σ Z</translation>
    </message>
</context>
<context>
    <name>GeoreferenceAlgorithm</name>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Camera positions (CSV)</source>
        <translation>Posizioni delle camere (CSV)</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="98"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="99"/>
        <source>GCP residuals</source>
        <translation>Residui dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="100"/>
        <source>Camera centres (world)</source>
        <translation>Centri di presa (mondo)</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="190"/>
        <source>outlier left out: {}</source>
        <translation>valore anomalo escluso: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="145"/>
        <source>CRS {}; control RMSE XY {} m, Z {} m; check RMSE XY {} m, Z {} m</source>
        <translation>SR {}; appoggio RMSE XY {} m, Z {} m; controllo RMSE XY {} m, Z {} m</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="178"/>
        <source>GCP layer {} lacks the field &apos;{}&apos; (needs name, image, px, py)</source>
        <translation>Al layer dei punti d'appoggio {} manca il campo '{}' (servono name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Georeference</source>
        <translation>Georeferenzia</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Aligned workspace</source>
        <translation>Area di lavoro allineata</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Ground control file</source>
        <translation>File dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Ground control layer</source>
        <translation>Layer dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Check points</source>
        <translation>Punti di controllo</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Use EXIF GPS positions</source>
        <translation>Usa le posizioni GPS EXIF</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Target CRS</source>
        <translation>SR di destinazione</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Refine camera calibration</source>
        <translation>Affina la calibrazione della camera</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>GCP pixels measured on upright photos</source>
        <translation>Pixel dei GCP misurati sulle foto raddrizzate</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="134"/>
        <source>Give ground control (Ground control file or layer: GCPS, GCP_LAYER) and/or camera positions (Camera positions (CSV) or Use EXIF GPS positions: CAMERA_POSITIONS, USE_EXIF_GPS)</source>
        <translation>Indica i punti d'appoggio (File o Layer dei punti d'appoggio: GCPS, GCP_LAYER) e/o le posizioni delle camere (Posizioni delle camere (CSV) o Usa le posizioni GPS EXIF: CAMERA_POSITIONS, USE_EXIF_GPS)</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Reference orthophoto</source>
        <translation>Ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Reference DSM</source>
        <translation>DSM di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Reference resolution for web layers (m, 0: auto)</source>
        <translation>Risoluzione di riferimento per layer web (m, 0: auto)</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Area to fetch from web layers</source>
        <translation>Area da scaricare dai layer web</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="101"/>
        <source>Automatic GCPs kept</source>
        <translation>GCP automatici mantenuti</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="164"/>
        <source>Automatic control needs both a reference orthophoto and a reference DSM (REFERENCE_ORTHO, REFERENCE_DSM); {} is missing</source>
        <translation>Il controllo automatico richiede sia un'ortofoto sia un DSM di riferimento (REFERENCE_ORTHO, REFERENCE_DSM); manca {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="177"/>
        <source>Target CRS {} is not used: automatic control georeferences in the reference orthophoto&apos;s CRS {}</source>
        <translation>Il SR di destinazione {} non è usato: il controllo automatico georeferenzia nel SR {} dell'ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="194"/>
        <source>Automatic control: {} automatic GCPs kept; CRS {}; check RMSE XY {} m, Z {} m</source>
        <translation>Controllo automatico: {} GCP automatici mantenuti; SR {}; RMSE di controllo XY {} m, Z {} m</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="129"/>
        <source>Reference DSM {} given alone (DEM control) must be a raster file on disk; a web layer is fetched only for the automatic control, with a reference orthophoto</source>
        <translation>Il DSM di riferimento {} fornito da solo (controllo DEM) deve essere un file raster su disco; un layer web viene scaricato solo per il controllo automatico, con un'ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Fixes the aligned block in a real coordinate reference system with ground control points (GCPs) and/or camera positions, used inside the bundle adjustment so that they also remove the block&apos;s drift and bending, which a 7-parameter (Helmert) transform cannot. Check points take no part in the adjustment: they are triangulated afterwards and compared with their surveyed coordinates.

Ground control file: an OpenDroneMap gcp_list.txt (CRS line, then &apos;x y z px py image [name]&apos;) or a CSV points file with a matching &apos;&lt;name&gt;_observations.csv&apos;. Ground control layer: alternatively a point layer with one feature per observation and fields name, image, px, py (optional z, sx, sy, sz, role).
Check points: comma-separated names that become check points.
Camera positions: CSV &apos;image,x,y,z[,sigma]&apos; (optional CRS line). Use EXIF GPS positions: use the photos&apos; GPS.
Target CRS: default the ground control file&apos;s. Refine camera calibration: let the adjustment refine focal length, principal point and distortion.
GCP pixels measured on upright photos: tick when the pixel coordinates were measured on the photos shown upright by their EXIF orientation, as web browsers and photo viewers show them; they are turned into the stored pixel grid of each photo (photos stored without a turn are unchanged).
Outliers (a wrong observation, a typo in a coordinate) are detected, named in the log and left out.

Given a reference orthophoto and a reference DSM (any raster layer: a file, or a WMS, XYZ or WCS layer, which is saved for the block&apos;s extent to georef/reference-ortho.tif and georef/reference-dsm.tif), the block is georeferenced with no hand-picked GCP, as &apos;Automatic control from a reference orthophoto&apos; does; the result is in the reference orthophoto&apos;s CRS (a Web Mercator or geographic layer is saved in the DSM&apos;s CRS, else in the UTM zone). Ground control given as well is not used to fix the block: all its points become check points, an independent measure of the automatic control. Camera positions or Use EXIF GPS positions give the rough position (else EXIF GPS when three photos carry it, else rotation and scale are searched). The calibration is refined in any case (focal length and distortion: the automatic GCPs determine them).
A reference DSM given alone (a DEM file in any projected CRS, heights in metres or feet) adds DEM control: after the adjustment the block&apos;s sparse points are co-registered on it (shift, tilt, dome) and the block is adjusted again with DEM-derived control points (dem001, ...), which remove tilt, height offset and doming the photos cannot see; the co-registration is logged and saved to georef/dem_control.json. Heights: the control points&apos; when there are any, else the DEM&apos;s (camera positions&apos; heights are moved onto it). Without GCPs or camera positions the photos&apos; EXIF GPS place the block. A DEM off the block or too coarse for it is refused before the adjustment.
Reference resolution: metres per pixel a web layer is saved at (0: 0.25 m; the DSM at twice that, at least 0.5 m). Area to fetch: the extent a web layer is saved for; empty: the photos&apos; EXIF GPS positions plus a margin, else the other reference&apos;s extent.
Outputs: besides the usual ones, the number of automatic GCPs the adjustment kept (none without automatic control).</source>
        <translation>Fissa il blocco allineato in un sistema di riferimento reale con punti d'appoggio (GCP) e/o posizioni delle camere, usati all'interno della compensazione a stelle proiettive in modo che eliminino anche la deriva e la flessione del blocco, cosa che una trasformazione a 7 parametri (Helmert) non può fare. I punti di controllo non partecipano alla compensazione: vengono triangolati in seguito e confrontati con le loro coordinate rilevate.

File dei punti d'appoggio: un gcp_list.txt di OpenDroneMap (riga del SR, poi 'x y z px py image [name]') o un file CSV di punti con il corrispondente '&lt;name&gt;_observations.csv'. Layer dei punti d'appoggio: in alternativa un layer di punti con un elemento per misura e i campi name, image, px, py (facoltativi z, sx, sy, sz, role).
Punti di controllo: nomi separati da virgole che diventano punti di controllo.
Posizioni delle camere: CSV 'image,x,y,z[,sigma]' (riga del SR facoltativa). Usa le posizioni GPS EXIF: usa il GPS delle foto.
SR di destinazione: predefinito quello del file dei punti d'appoggio. Affina la calibrazione della camera: la compensazione affina focale, punto principale e distorsione.
Pixel dei GCP misurati sulle foto raddrizzate: da spuntare quando le coordinate pixel sono state misurate sulle foto mostrate diritte secondo il loro orientamento EXIF, come le mostrano i browser e i visualizzatori di foto; sono convertite nella griglia di pixel memorizzata di ogni foto (le foto memorizzate senza rotazione restano invariate).
I valori anomali (una misura errata, un errore di battitura in una coordinata) sono individuati, nominati nel registro ed esclusi.

Con un'ortofoto di riferimento e un DSM di riferimento (un layer raster qualsiasi: un file, o un layer WMS, XYZ o WCS, che viene salvato per l'estensione del blocco in georef/reference-ortho.tif e georef/reference-dsm.tif), il blocco viene georeferenziato senza punti d'appoggio scelti a mano, come fa 'Punti di controllo automatici da un'ortofoto di riferimento'; il risultato è nel SR dell'ortofoto di riferimento (un layer Web Mercator o geografico viene salvato nel SR del DSM, altrimenti nella zona UTM). I punti d'appoggio forniti in più non fissano il blocco: tutti i loro punti diventano punti di controllo, una misura indipendente del controllo automatico. Posizioni delle camere o Usa le posizioni GPS EXIF danno la posizione approssimativa (altrimenti il GPS EXIF quando tre foto lo hanno, altrimenti si cercano rotazione e scala). La calibrazione viene affinata in ogni caso (focale e distorsione: le determinano i GCP automatici).
Un DSM di riferimento fornito da solo (un file DEM in un SR proiettato qualsiasi, quote in metri o piedi) aggiunge il controllo DEM: dopo la compensazione i punti sparsi del blocco vengono co-registrati su di esso (traslazione, inclinazione, cupola) e il blocco viene compensato di nuovo con punti d'appoggio derivati dal DEM (dem001, ...), che eliminano l'inclinazione, lo scostamento in quota e l'effetto cupola che le foto non possono vedere; la co-registrazione viene riportata nel registro e salvata in georef/dem_control.json. Quote: quelle dei punti d'appoggio quando ce ne sono, altrimenti quelle del DEM (le quote delle posizioni delle camere vengono spostate su di esso). Senza GCP né posizioni delle camere il GPS EXIF delle foto posiziona il blocco. Un DEM fuori dal blocco o troppo grossolano per esso viene rifiutato prima della compensazione.
Risoluzione di riferimento: metri per pixel con cui si salva un layer web (0: 0,25 m; il DSM al doppio, almeno 0,5 m). Area da scaricare: l'estensione per cui si salva un layer web; vuota: le posizioni GPS EXIF delle foto più un margine, altrimenti l'estensione dell'altro riferimento.
Output: oltre ai consueti, il numero di GCP automatici mantenuti dalla compensazione (nessuno senza controllo automatico).</translation>
    </message>
</context>
<context>
    <name>OrthorectifyImageAlgorithm</name>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="73"/>
        <source>Image</source>
        <translation>Immagine</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>DSM</source>
        <translation>DSM</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Mode</source>
        <translation>Modalità</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="94"/>
        <source>Orthophoto</source>
        <translation>Ortofoto</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="95"/>
        <source>GCP residuals</source>
        <translation>Residui dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="97"/>
        <source>GCP residual RMSE (pixels)</source>
        <translation>RMSE dei residui dei punti d'appoggio (pixel)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="99"/>
        <source>Planar rectification: 95th percentile of its offset from the true position (CRS units)</source>
        <translation>Raddrizzamento piano: 95° percentile del suo scostamento dalla posizione vera (unità del SR)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="128"/>
        <source>RESIDUALS must be a GeoPackage (.gpkg) file, got {}</source>
        <translation>RESIDUALS deve essere un file GeoPackage (.gpkg), ricevuto {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="143"/>
        <source>{} ({}): {:.2f} px</source>
        <translation>{} ({}): {:.2f} px</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="110"/>
        <source>GCP layer {} lacks the field &apos;{}&apos; (needs name, image, px, py)</source>
        <translation>Al layer dei punti d'appoggio {} manca il campo '{}' (servono name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Orthorectify image</source>
        <translation>Ortorettifica immagine</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Ground control file</source>
        <translation>File dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Ground control point layer</source>
        <translation>Layer dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Known orientation</source>
        <translation>Orientamento noto</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Focal length (mm)</source>
        <translation>Focale (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Sensor width (mm)</source>
        <translation>Larghezza del sensore (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Resolution (0 = automatic)</source>
        <translation>Risoluzione (0 = automatica)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Output CRS</source>
        <translation>SR di output</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>True orthophoto on the DSM</source>
        <translation>Ortofoto vera sul DSM</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Planar rectification (flat ground)</source>
        <translation>Raddrizzamento piano (terreno piatto)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Search radius (m)</source>
        <translation>Raggio di ricerca (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="98"/>
        <source>Automatic GCPs used</source>
        <translation>GCP automatici usati</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="117"/>
        <source>Give ground control points observed in the image (Ground control file or Ground control point layer: GCPS, GCP_LAYER), its Known orientation (ORIENTATION) or a Reference orthophoto for automatic control (REFERENCE_ORTHO)</source>
        <translation>Indicare punti d'appoggio misurati nell'immagine (File dei punti d'appoggio o Layer dei punti d'appoggio: GCPS, GCP_LAYER), il suo orientamento noto (ORIENTATION) o un'ortofoto di riferimento per il controllo automatico (REFERENCE_ORTHO)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Orthorectifies one photograph — also one that is not part of any block, such as a single oblique or an old print — on an existing DSM, for example an airborne laser scanning (ALS) DSM in any CRS (it is reprojected on the fly).

The camera's position and attitude come from ground control points observed in the photo (space resection: at least 4 points; one wrong point among 5 or more is found and left out; with 6 or more the focal length and the radial distortion k1 are estimated too where the points determine them), or from a known orientation.

Image: the photo. DSM: height raster (needed for a true orthophoto).
Ground control file: an OpenDroneMap gcp_list.txt or CSV points file with observations in this image; or Ground control point layer: a point layer with one feature per observation and fields name, image, px, py (optional z, role; pixel origin at the upper-left corner, y down).
Known orientation: instead of GCPs, a file with x y z omega phi kappa (degrees, photogrammetric convention; a header row as Pix4D writes it, or JSON), optionally focal_mm, sensor_width_mm, cx, cy, k1, k2, p1, p2 and a CRS line.
Reference orthophoto (automatic control): with no GCPs and no known orientation, the photo is matched to this orthophoto (any CRS, any resolution; the DSM is then the reference DSM) and the matches become automatic GCPs (auto_001, ...) for the space resection: no hand-picked point, the heading need not be known, obliques work too, and the focal length is estimated when the photo has none. Rough location: a point on the ground the photo shows (any CRS; empty = anywhere on the reference); Search radius: how far off it may be (metres). The log says how many matches survived each step; the GCP residuals list the automatic GCPs.
Focal length and Sensor width: interior orientation in mm (the sensor's long side); 0 or empty = the EXIF focal length.
Mode: a true orthophoto on the DSM, or a planar (projective) rectification through the GCPs for comparison on flat ground; with a DSM the log and the output 'Planar rectification: 95th percentile of its offset' say how far the planar result is off because of relief.
Resolution: cell size in CRS units (0 = the ground sample distance).
Output CRS: default the CRS of the GCPs or of the known orientation.
GCP residuals: GeoPackage of the GCPs with their residuals in pixels (and metres on the plane).</source>
        <translation>Ortorettifica una fotografia — anche una che non fa parte di alcun blocco, come una singola obliqua o una vecchia stampa — su un DSM esistente, ad esempio un DSM da laser scanning aereo (ALS) in qualsiasi SR (riproiettato al volo).

Posizione e assetto della camera derivano dai punti d'appoggio misurati nella foto (resezione spaziale: almeno 4 punti; un punto errato su 5 o più viene individuato ed escluso; con 6 o più si stimano anche la focale e la distorsione radiale k1 dove i punti le determinano), oppure da un orientamento noto.

Immagine: la foto. DSM: raster delle quote (necessario per un'ortofoto vera).
File dei punti d'appoggio: un gcp_list.txt di OpenDroneMap o un file CSV di punti con misure in questa immagine; oppure Layer dei punti d'appoggio: un layer di punti con un elemento per misura e i campi name, image, px, py (facoltativi z, role; origine dei pixel nell'angolo in alto a sinistra, y verso il basso).
Orientamento noto: al posto dei punti d'appoggio, un file con x y z omega phi kappa (gradi, convenzione fotogrammetrica; una riga di intestazione come la scrive Pix4D, o JSON), facoltativamente focal_mm, sensor_width_mm, cx, cy, k1, k2, p1, p2 e una riga del SR.
Ortofoto di riferimento (controllo automatico): senza punti d'appoggio e senza orientamento noto, la foto viene abbinata a questa ortofoto (qualsiasi SR, qualsiasi risoluzione; il DSM è allora il DSM di riferimento) e le corrispondenze diventano punti d'appoggio automatici (auto_001, ...) per la resezione spaziale: nessun punto scelto a mano, la direzione di presa non deve essere nota, funzionano anche le oblique, e la focale viene stimata quando la foto non ne ha. Posizione approssimativa: un punto sul terreno che la foto mostra (qualsiasi SR; vuoto = ovunque sul riferimento); Raggio di ricerca: quanto può essere lontano (metri). Il registro dice quante corrispondenze hanno superato ogni passo; i residui dei punti d'appoggio elencano i punti d'appoggio automatici.
Focale e Larghezza del sensore: orientamento interno in mm (il lato lungo del sensore); 0 o vuoto = la focale EXIF.
Modalità: un'ortofoto vera sul DSM, o un raddrizzamento piano (proiettivo) tramite i punti d'appoggio per confronto su terreno piatto; con un DSM il registro e il risultato 'Raddrizzamento piano: 95° percentile del suo scostamento' dicono di quanto il risultato piano si discosta a causa del rilievo.
Risoluzione: dimensione della cella in unità del SR (0 = il GSD).
SR di output: predefinito il SR dei punti d'appoggio o dell'orientamento noto.
Residui dei punti d'appoggio: GeoPackage dei punti d'appoggio con i loro residui in pixel (e in metri sul piano).</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Reference orthophoto</source>
        <translation>Ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Rough location</source>
        <translation>Posizione approssimativa</translation>
    </message>
</context>
<context>
    <name>PhotoPanel</name>
    <message>
        <location filename="../ui/photo_viewer.py" line="472"/>
        <source>Only photos that probably see the point</source>
        <translation>Solo le foto che probabilmente vedono il punto</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="475"/>
        <source>Fit</source>
        <translation>Adatta</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="475"/>
        <source>Show the whole photo (F)</source>
        <translation>Mostra l'intera foto (F)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="476"/>
        <source>Zoom to point</source>
        <translation>Zoom sul punto</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="476"/>
        <source>Zoom to the observation or prediction (Z)</source>
        <translation>Zoom sulla misura o sulla previsione (Z)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="478"/>
        <source>Confirm</source>
        <translation>Conferma</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="478"/>
        <source>Accept the predicted position (Space)</source>
        <translation>Accetta la posizione prevista (Spazio)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="480"/>
        <source>Confirm &amp;&amp; next</source>
        <translation>Conferma &amp;&amp; avanti</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="480"/>
        <source>Accept the prediction and show the next photo to place (Enter)</source>
        <translation>Accetta la previsione e mostra la prossima foto da misurare (Invio)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="483"/>
        <source>Remove</source>
        <translation>Rimuovi</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="483"/>
        <source>Remove the observation in this photo (Delete)</source>
        <translation>Rimuovi la misura in questa foto (Canc)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="683"/>
        <source>{} (predicted)</source>
        <translation>{} (previsto)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="589"/>
        <source>Shown upright (EXIF orientation {}: stored {} x {} px); pixel coordinates are those of the stored grid, as COLMAP and gcp_list.txt use them</source>
        <translation>Mostrata raddrizzata (orientamento EXIF {}: salvata {} x {} px); le coordinate pixel sono quelle della griglia salvata, come le usano COLMAP e gcp_list.txt</translation>
    </message>
</context>
<context>
    <name>PrepareImagesAlgorithm</name>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Folder of images</source>
        <translation>Cartella delle immagini</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Workspace folder</source>
        <translation>Cartella dell'area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Flag images below this fraction of the set&apos;s median blur score</source>
        <translation>Segnala le immagini sotto questa frazione del punteggio di nitidezza mediano dell'insieme</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Fiducial mark type</source>
        <translation>Tipo di marca fiduciale</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Fiducial positions</source>
        <translation>Posizioni delle marche fiduciali</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Template image of one fiducial mark</source>
        <translation>Immagine modello di una marca fiduciale</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Scan resolution in dpi when not in the files (0 = from the files)</source>
        <translation>Risoluzione di scansione in dpi se non nei file (0 = dai file)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="116"/>
        <source>Folder of prepared images</source>
        <translation>Cartella delle immagini preparate</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="117"/>
        <source>Flagged images</source>
        <translation>Immagini segnalate</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="118"/>
        <source>Excluded images</source>
        <translation>Immagini escluse</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="119"/>
        <source>Screening record (JSON)</source>
        <translation>Registro del controllo (JSON)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="156"/>
        <source>{} images: {} flagged, {} excluded, {} in the prepared folder</source>
        <translation>{} immagini: {} segnalate, {} escluse, {} nella cartella preparata</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="158"/>
        <source>Blurriest first (blur score, % of the set&apos;s median):</source>
        <translation>Le più sfocate per prime (punteggio di nitidezza, % della mediana dell'insieme):</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="166"/>
        <source>Prepared scans: {} x {} px, pixel size {:.6g} {}{}</source>
        <translation>Scansioni preparate: {} x {} px, dimensione del pixel {:.6g} {}{}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Prepare images</source>
        <translation>Prepara immagini</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="151"/>
        <source>MASKS layer &apos;{}&apos;</source>
        <translation>layer MASKS '{}'</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="186"/>
        <source>feature {}</source>
        <translation>elemento {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="190"/>
        <source>MASKS layer &apos;{}&apos;: {} has no geometry: skipped</source>
        <translation>layer MASKS '{}': {} non ha geometria: saltato</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="193"/>
        <source>MASKS layer &apos;{}&apos;: {} is a {} geometry, not a polygon</source>
        <translation>layer MASKS '{}': {} è una geometria {}, non un poligono</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Smallest blur score (0 = relative only)</source>
        <translation>Punteggio di nitidezza minimo (0 = solo relativo)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Leave flagged images out</source>
        <translation>Escludi le immagini segnalate</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="92"/>
        <source>Mask polygons</source>
        <translation>Poligoni di maschera</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="95"/>
        <source>Sky masks for oblique photos</source>
        <translation>Maschere del cielo per foto oblique</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="96"/>
        <source>Scanned film (fiducial marks)</source>
        <translation>Pellicola scansionata (marche fiduciali)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="97"/>
        <source>Fiducial coordinates (mm)</source>
        <translation>Coordinate delle marche fiduciali (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="113"/>
        <source>Prepared images</source>
        <translation>Immagini preparate</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Calibrated focal length (mm)</source>
        <translation>Focale calibrata (mm)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Screens a folder of photographs for blur and exposure and, for scanned historical film, finds the fiducial marks and resamples every scan into one camera frame. The result is a folder of prepared images for &apos;Align images&apos;, and the Workspace folder, which records a decision per image (screening.json) for the accuracy report.

The blur score is the variance of the Laplacian on a grey copy 1024 px wide, 90th percentile of an 8 x 6 grid of tiles (sky or water in part of a frame does not count against it). Higher is sharper. An image is flagged &apos;blurry&apos; below a fraction of the median of the set (Flag images below this fraction of the set&apos;s median blur score, advanced), or below the Smallest blur score when that is set (0 = only relative to the set; absolute scores depend on the scene: sand scores far lower than roofs).
Images with more than 5 % clipped highlights or shadows, a mean brightness far from the set&apos;s, or a very small dynamic range are flagged for their exposure. With &apos;Leave flagged images out&apos; ticked they are left out of the prepared folder; otherwise they are kept and only reported.

Mask polygons: optional polygon layer of areas to ignore in the alignment and the orthophoto (a boom, the drone&apos;s shadow, a date stamp, a frame border), in the image&apos;s pixel coordinates: origin at the upper-left corner of the image, x right, y down, or y = -row as the QGIS georeferencer shows a photo (detected when every y is &lt;= 0). A text field &apos;image&apos; names the image a polygon belongs to; empty (or no such field) applies it to every image. The polygons are written into the per-image masks (workspace/masks/&lt;image&gt;.png, merged with any mask already there): &apos;Align images&apos; finds no features under them, the orthophoto does not use those pixels, and blur and exposure are measured outside them. For scanned film the coordinates are those of the prepared images (the common fiducial frame, so one polygon fits every frame).
Sky masks for oblique photos: the sky (clouds included) and the haze along the horizon are found automatically and written into the per-image masks, so that &apos;Align images&apos; takes no tie points from clouds that move between shots; a photo without sky (looking straight down) gets no sky mask.

Scanned film (fiducial marks): fiducial marks (crosses, dots, dots in circles; in the corners and/or the side middles, or like a template image of one mark) are found to a fraction of a pixel, each scan is resampled by an affine transform into the common fiducial frame, all with the same size and the principal point at the centre, and masks (workspace/masks) hide the film border, data strips and the marks from matching. Fiducial coordinates: the calibration certificate&apos;s calibrated fiducial coordinates in mm, as a file path or pasted text, one &apos;id x y&apos; line per mark (x right, y up), optionally &apos;PP x y&apos; (principal point) and &apos;focal f&apos;. Without them the mean layout of the set is used, centred on the fiducial centre. With the Calibrated focal length (0 = unknown; or &apos;focal&apos; in the certificate) the prepared images carry the focal length in pixels for the alignment.

Prepared images: the folder of prepared images (replaced as a whole; it must be new, empty or written by an earlier run); when skipped, &lt;workspace&gt;/prepared.</source>
        <translation>Controlla una cartella di fotografie per sfocatura ed esposizione e, per le pellicole storiche scansionate, trova le marche fiduciali e ricampiona ogni scansione in un unico fotogramma della camera. Il risultato è una cartella di immagini preparate per 'Allinea immagini' e la Cartella dell'area di lavoro, che registra una decisione per immagine (screening.json) per il rapporto di accuratezza.

Il punteggio di nitidezza è la varianza del laplaciano su una copia in grigio larga 1024 px, 90° percentile di una griglia di 8 x 6 tasselli (cielo o acqua in una parte del fotogramma non vanno a suo sfavore). Più alto è più nitido. Un'immagine è segnalata come 'sfocata' sotto una frazione della mediana dell'insieme (Segnala le immagini sotto questa frazione del punteggio di nitidezza mediano dell'insieme, avanzato), o sotto il Punteggio di nitidezza minimo se impostato (0 = solo relativo all'insieme; i punteggi assoluti dipendono dalla scena: la sabbia ottiene molto meno dei tetti).
Vengono segnalate per l'esposizione le immagini con più del 5 % di luci o ombre tagliate, una luminosità media lontana da quella dell'insieme o una gamma dinamica molto ridotta. Con 'Escludi le immagini segnalate' attivo sono escluse dalla cartella preparata; altrimenti vengono mantenute e solo riportate.

Poligoni di maschera: layer poligonale opzionale delle aree che allineamento e ortofoto devono ignorare (un braccio, l'ombra del drone, un timbro con la data, un bordo del fotogramma), nelle coordinate pixel dell'immagine: origine nell'angolo superiore sinistro, x verso destra, y verso il basso, oppure y = -riga come il georeferenziatore di QGIS mostra una foto (riconosciuto quando ogni y è &lt;= 0). Un campo di testo 'image' indica l'immagine a cui appartiene un poligono; vuoto (o senza tale campo) vale per ogni immagine. I poligoni vengono scritti nelle maschere per immagine (workspace/masks/&lt;immagine&gt;.png, unite a una maschera già presente): 'Allinea immagini' non trova caratteristiche sotto di essi, l'ortofoto non usa quei pixel, e nitidezza ed esposizione vengono misurate al di fuori. Per la pellicola scansionata valgono le coordinate delle immagini preparate (il riferimento comune delle marche fiduciali, così un poligono vale per ogni fotogramma).
Maschere del cielo per foto oblique: il cielo (nuvole comprese) e la foschia lungo l'orizzonte sono trovati automaticamente e scritti nelle maschere per immagine, così 'Allinea immagini' non prende punti di legame dalle nuvole che si spostano tra uno scatto e l'altro; una foto senza cielo (rivolta verso il basso) non riceve una maschera del cielo.

Pellicola scansionata (marche fiduciali): le marche fiduciali (croci, punti, punti in cerchi; negli angoli e/o a metà dei lati, o come un'immagine modello di una marca) sono trovate con precisione sub-pixel, ogni scansione è ricampionata con una trasformazione affine nel fotogramma fiduciale comune, tutte della stessa dimensione e con il punto principale al centro, e delle maschere (workspace/masks) nascondono alla corrispondenza il bordo della pellicola, le strisce di dati e le marche. Coordinate delle marche fiduciali: le coordinate calibrate delle marche fiduciali del certificato di calibrazione in mm, come percorso di file o testo incollato, una riga 'id x y' per marca (x a destra, y in alto), facoltativamente 'PP x y' (punto principale) e 'focal f'. Senza di esse si usa la disposizione media dell'insieme, centrata sul centro fiduciale. Con la Focale calibrata (0 = sconosciuta; o 'focal' nel certificato) le immagini preparate riportano la focale in pixel per l'allineamento.

Immagini preparate: la cartella delle immagini preparate (sostituita per intero; deve essere nuova, vuota o scritta da un'esecuzione precedente); se omessa, &lt;workspace&gt;/prepared.</translation>
    </message>
</context>
<context>
    <name>ReliefVisualisationAlgorithm</name>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="43"/>
        <source>Workspace folder</source>
        <translation>Cartella dell'area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>Surface</source>
        <translation>Superficie</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>DTM</source>
        <translation>DTM</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>DSM</source>
        <translation>DSM</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>Visualisation</source>
        <translation>Visualizzazione</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="55"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="76"/>
        <source>Give a workspace folder, or an elevation raster and where to write the visualisation</source>
        <translation>Indica una cartella dell'area di lavoro, oppure un raster delle quote e dove scrivere la visualizzazione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisation</source>
        <translation>Visualizzazione del rilievo</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="41"/>
        <source>VAT blend</source>
        <translation>Miscela VAT</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>Elevation raster</source>
        <translation>Raster delle quote</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="52"/>
        <source>Relief raster</source>
        <translation>Raster del rilievo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisations for reading earthworks, hollow ways, ridge and furrow and field boundaries, computed with rvt-py (the Relief Visualization Toolbox&apos;s library) with RVT&apos;s default parameters, converted from the 1 m DEMs RVT was made for to this raster&apos;s cell size.

Workspace folder: a workspace with a DTM (Build DTM) or DSM.
Elevation raster: any DTM/DSM in a projected CRS instead (optional).
Surface: the workspace&apos;s DTM (bare earth, default) or DSM.
Visualisation: sky-view factor, openness (positive, negative), simple local relief model, multi-scale relief model, multi-direction hillshade, local dominance, or the VAT blend (visualisation for archaeological topography).
Relief raster: where to write it (default: &lt;workspace&gt;/terrain/relief/&lt;surface&gt;-&lt;visualisation&gt;.tif).</source>
        <translation>Visualizzazioni del rilievo per leggere terrapieni, strade incassate, campi baulati e confini di campi, calcolate con rvt-py (la libreria del Relief Visualization Toolbox) con i parametri predefiniti di RVT, convertiti dai DEM a 1 m per cui RVT è fatto alla dimensione di cella di questo raster.

Cartella dell'area di lavoro: un'area di lavoro con DTM (Genera DTM) o DSM.
Raster delle quote: in alternativa qualsiasi DTM/DSM in un SR proiettato (facoltativo).
Superficie: il DTM dell'area di lavoro (suolo nudo, predefinito) o il DSM.
Visualizzazione: fattore di vista del cielo, apertura (positiva, negativa), modello semplice del rilievo locale, modello del rilievo a più scale, ombreggiatura da più direzioni, dominanza locale o la miscela VAT (visualizzazione per la topografia archeologica).
Raster del rilievo: dove scriverlo (predefinito: &lt;workspace&gt;/terrain/relief/&lt;surface&gt;-&lt;visualisation&gt;.tif).</translation>
    </message>
</context>
<context>
    <name>Report</name>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>height (m)</source>
        <translation>quota (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Summary</source>
        <translation>Riepilogo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Orientation quality</source>
        <translation>Qualità dell'orientamento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Georeferencing</source>
        <translation>Georeferenziazione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Uncertainty</source>
        <translation>Incertezza</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Products</source>
        <translation>Prodotti</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>images aligned</source>
        <translation>immagini allineate</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean reprojection error</source>
        <translation>errore medio di riproiezione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ground sample distance</source>
        <translation>risoluzione al suolo (GSD)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>area</source>
        <translation>area</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>check RMSE XY</source>
        <translation>RMSE di controllo XY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>check RMSE Z</source>
        <translation>RMSE di controllo Z</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>NSSDA horizontal 95 %</source>
        <translation>NSSDA orizzontale 95 %</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>NSSDA vertical 95 %</source>
        <translation>NSSDA verticale 95 %</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ASPRS 2014 horizontal class</source>
        <translation>classe orizzontale ASPRS 2014</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera position RMSE XY (the block&apos;s fit to the positions)</source>
        <translation>RMSE XY delle posizioni delle camere (adattamento del blocco alle posizioni)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>tie point σXY / σZ (median; predicted ground uncertainty, datum included)</source>
        <translation>σXY / σZ dei punti di legame (mediana; incertezza prevista al suolo, datum incluso)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM valid fraction</source>
        <translation>frazione valida del DSM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ArchaeoOrtho report — {}</source>
        <translation>Rapporto ArchaeoOrtho — {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>no aligned model: run &apos;Align images&apos;</source>
        <translation>nessun modello allineato: esegui 'Allinea immagini'</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>no DSM / orthomosaic yet</source>
        <translation>ancora nessun DSM / ortomosaico</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>{} of {} images aligned, mean reprojection error {} px</source>
        <translation>{} di {} immagini allineate, errore medio di riproiezione {} px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>generated</source>
        <translation>generato</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>At a glance</source>
        <translation>In sintesi</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Skipped:</source>
        <translation>Saltata:</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>automatic control points</source>
        <translation>punti d'appoggio automatici</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Where the automatic GCPs lie (triangles, coloured by their horizontal residual after the adjustment), the ones the adjustment rejected (red) and the candidates dropped before it (grey): a change between the epochs, a height the DSM does not give, a point found in one photo only.</source>
        <translation>Dove si trovano i GCP automatici (triangoli, colorati secondo il residuo orizzontale dopo la compensazione), quelli scartati dalla compensazione (rosso) e i candidati esclusi prima (grigio): un cambiamento tra le epoche, una quota che il DSM non fornisce, un punto trovato in una sola foto.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>step</source>
        <translation>passo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>matches / points</source>
        <translation>corrispondenze / punti</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dropped because</source>
        <translation>escluso perché</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>candidates</source>
        <translation>candidati</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dropped candidates</source>
        <translation>candidati esclusi</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>automatic GCPs (colour: XY residual)</source>
        <translation>GCP automatici (colore: residuo XY)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>XY residual (m)</source>
        <translation>residuo XY (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Automatic control</source>
        <translation>Controllo automatico</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>rejected by the adjustment</source>
        <translation>scartati dalla compensazione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>set</source>
        <translation>insieme</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE X</source>
        <translation>RMSE X</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE Y</source>
        <translation>RMSE Y</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE Z</source>
        <translation>RMSE Z</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE XY</source>
        <translation>RMSE XY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean dX</source>
        <translation>dX medio</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean dY</source>
        <translation>dY medio</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean dZ</source>
        <translation>dZ medio</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>name</source>
        <translation>nome</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>role</source>
        <translation>ruolo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>status</source>
        <translation>stato</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dXY</source>
        <translation>dXY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>obs</source>
        <translation>oss.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean px</source>
        <translation>px medi</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>max px</source>
        <translation>px max</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image residuals (px)</source>
        <translation>residui in immagine (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>residual vectors</source>
        <translation>vettori dei residui</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>group</source>
        <translation>gruppo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ XY</source>
        <translation>σ XY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>rigid fit σ XY</source>
        <translation>σ XY dell'adattamento rigido</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>rigid fit σ Z</source>
        <translation>σ Z dell'adattamento rigido</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>floor XY</source>
        <translation>minimo XY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>floor Z</source>
        <translation>minimo Z</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>placeholders</source>
        <translation>segnaposto</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>estimated from</source>
        <translation>stimato da</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image σ (px)</source>
        <translation>σ in immagine (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>left out as suspect</source>
        <translation>esclusi come sospetti</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE XY (radial)</source>
        <translation>RMSE XY (radiale)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE 3D</source>
        <translation>RMSE 3D</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>max dXY</source>
        <translation>dXY max</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>max |dZ|</source>
        <translation>|dZ| max</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera centres</source>
        <translation>centri di presa</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image</source>
        <translation>immagine</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>used</source>
        <translation>usato</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>tie-point footprint</source>
        <translation>impronta dei punti di legame</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dZ (m)</source>
        <translation>dZ (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Residual vectors over the footprint</source>
        <translation>Vettori dei residui sull'impronta</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Outliers and suspect points</source>
        <translation>Valori anomali e punti sospetti</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Accuracy of the control given without sigmas, estimated from the data</source>
        <translation>Accuratezza dei punti d'appoggio dati senza sigma, stimata dai dati</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE per set</source>
        <translation>RMSE per insieme</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Outliers, suspect points and warnings</source>
        <translation>Valori anomali, punti sospetti e avvisi</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Control and check points</source>
        <translation>Punti d'appoggio e di controllo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Camera-position residuals</source>
        <translation>Residui delle posizioni delle camere</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>reprojection error (px)</source>
        <translation>errore di riproiezione (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>observations</source>
        <translation>osservazioni</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>track length (images per tie point)</source>
        <translation>lunghezza delle tracce (immagini per punto di legame)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>tie points</source>
        <translation>punti di legame</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>reprojection error and track length histograms</source>
        <translation>istogrammi dell'errore di riproiezione e della lunghezza delle tracce</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Left: reprojection error of every tie-point observation (clipped at the 99.5th percentile). Right: number of images per tie point.</source>
        <translation>A sinistra: errore di riproiezione di ogni osservazione dei punti di legame (troncato al 99,5° percentile). A destra: numero di immagini per punto di legame.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean error (px)</source>
        <translation>errore medio (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>reprojection error per image</source>
        <translation>errore di riproiezione per immagine</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Mean reprojection error (red: more than twice the median) and tie-point observations per image.</source>
        <translation>Errore medio di riproiezione (rosso: più del doppio della mediana) e osservazioni dei punti di legame per immagine.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera</source>
        <translation>camera</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mode</source>
        <translation>modalità</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>parameter</source>
        <translation>parametro</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>given</source>
        <translation>dato</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>final</source>
        <translation>finale</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>moved</source>
        <translation>spostamento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>moved (σ)</source>
        <translation>spostamento (σ)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image × image</source>
        <translation>immagine × immagine</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera positions</source>
        <translation>posizioni delle camere</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>shared tie points</source>
        <translation>punti di legame condivisi</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image connectivity</source>
        <translation>connettività delle immagini</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean reprojection error (px)</source>
        <translation>errore medio di riproiezione (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dZ (m): adjusted − given</source>
        <translation>dZ (m): compensato − dato</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Camera positions</source>
        <translation>Posizioni delle camere</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Image connectivity</source>
        <translation>Connettività delle immagini</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Interior orientation</source>
        <translation>Orientamento interno</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM preview with hillshade (sun from the north-west, 45°).</source>
        <translation>Anteprima del DSM con ombreggiatura (sole da nord-ovest, 45°).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>{} preview.</source>
        <translation>Anteprima: {}.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM</source>
        <translation>DSM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Orthomosaic</source>
        <translation>Ortomosaico</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>NSSDA accuracy at 95 % confidence (FGDC-STD-007.3-1998)</source>
        <translation>Accuratezza NSSDA al 95 % di confidenza (FGDC-STD-007.3-1998)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ASPRS positional accuracy class</source>
        <translation>Classe di accuratezza posizionale ASPRS</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur scores</source>
        <translation>valori di nitidezza</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Blur score per image (orange: flagged, red: excluded).</source>
        <translation>Valore di nitidezza per immagine (arancione: segnalata, rosso: esclusa).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur score (higher = sharper)</source>
        <translation>valore di nitidezza (più alto = più nitido)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>images, blurriest first</source>
        <translation>immagini, la più sfocata per prima</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur score</source>
        <translation>valore di nitidezza</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur / median</source>
        <translation>nitidezza / mediana</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>exposure</source>
        <translation>esposizione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dynamic range</source>
        <translation>gamma dinamica</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>flags</source>
        <translation>segnalazioni</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>decision</source>
        <translation>decisione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>model</source>
        <translation>modello</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>size (px)</source>
        <translation>dimensione (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>images</source>
        <translation>immagini</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>parameters (pixels; distortion unitless)</source>
        <translation>parametri (pixel; distorsione adimensionale)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>stage</source>
        <translation>fase</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>parameters</source>
        <translation>parametri</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>why</source>
        <translation>perché</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Image screening</source>
        <translation>Controllo delle immagini</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>median</source>
        <translation>mediana</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>time</source>
        <translation>tempo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>steps</source>
        <translation>passi</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>finished</source>
        <translation>terminato</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>{} images screened: {} flagged, {} excluded, {} kept (blurriest first).</source>
        <translation>{} immagini controllate: {} segnalate, {} escluse, {} mantenute (la più sfocata per prima).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Cameras and calibrated parameters</source>
        <translation>Camere e parametri calibrati</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images not aligned</source>
        <translation>Immagini non allineate</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Processing stages</source>
        <translation>Fasi di elaborazione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DTM preview</source>
        <translation>anteprima del DTM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DTM (bare earth) preview with hillshade.</source>
        <translation>Anteprima del DTM (terreno nudo) con ombreggiatura.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisations</source>
        <translation>Visualizzazioni del rilievo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisations (rvt-py, RVT&apos;s default parameters scaled to the cell size), in RVT&apos;s display ranges.</source>
        <translation>Visualizzazioni del rilievo (rvt-py, i parametri predefiniti di RVT scalati alla dimensione della cella), negli intervalli di visualizzazione di RVT.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Terrain (DTM)</source>
        <translation>Terreno (DTM)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>point standard deviations</source>
        <translation>deviazioni standard dei punti</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Left: distribution of the tie points' standard deviations. Right: σZ over the block, colours clipped at the 95th percentile (precision degrades where few images overlap and away from control).</source>
        <translation>A sinistra: distribuzione delle deviazioni standard dei punti di legame. A destra: σZ sul blocco, colori troncati al 95° percentile (la precisione cala dove poche immagini si sovrappongono e lontano dai punti d'appoggio).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σXY</source>
        <translation>σXY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cameras</source>
        <translation>camere</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ rot x (°)</source>
        <translation>σ rot. x (°)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ rot y (°)</source>
        <translation>σ rot. y (°)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ rot z (°)</source>
        <translation>σ rot. z (°)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σX (m)</source>
        <translation>σX (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σY (m)</source>
        <translation>σY (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σZ (m)</source>
        <translation>σZ (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>control</source>
        <translation>punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reference orthophoto</source>
        <translation>Ortofoto di riferimento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reference DSM</source>
        <translation>DSM di riferimento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Rough position (prior)</source>
        <translation>Posizione approssimata (a priori)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reference CRS</source>
        <translation>SR del riferimento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Common resolution of the match</source>
        <translation>Risoluzione comune dell'abbinamento</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>CRS</source>
        <translation>SR</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Source of the datum</source>
        <translation>Origine del datum</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Local frame offset (world = local + offset)</source>
        <translation>Offset del sistema locale (mondo = locale + offset)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie-point reprojection error after the adjustment</source>
        <translation>Errore di riproiezione dei punti di legame dopo la compensazione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>GCP observation reprojection error in the adjustment (mean; control held at its coordinates within its sigmas)</source>
        <translation>Errore di riproiezione delle osservazioni dei GCP nella compensazione (media; punti d'appoggio tenuti alle loro coordinate entro i loro sigma)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Mean reprojection error (mean over tie points of their mean error, as COLMAP reports it)</source>
        <translation>Errore medio di riproiezione (media sui punti di legame del loro errore medio, come lo riporta COLMAP)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reprojection error of the observations: mean / median / RMS</source>
        <translation>Errore di riproiezione delle osservazioni: media / mediana / RMS</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Largest reprojection error</source>
        <translation>Errore di riproiezione massimo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Track length: mean / median / max</source>
        <translation>Lunghezza delle tracce: media / mediana / massimo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Model</source>
        <translation>Modello</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>File</source>
        <translation>File</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Size</source>
        <translation>Dimensione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Resolution</source>
        <translation>Risoluzione</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Brightness step across the seamlines (median; before → after the radiometric correction)</source>
        <translation>Salto di luminosità attraverso le linee di giunzione (mediana; prima → dopo la correzione radiometrica)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Valid fraction (cells with data)</source>
        <translation>Frazione valida (celle con dati)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Valid fraction inside the camera centres&apos; convex hull (as the stage reports it)</source>
        <translation>Frazione valida entro l'inviluppo convesso dei centri di presa (come la riporta la fase)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Inside that hull: measured / interpolated (filled holes) / removed as blunders (dense/dsm-source.tif)</source>
        <translation>Entro tale inviluppo: misurate / interpolate (buchi riempiti) / rimosse come errori grossolani (dense/dsm-source.tif)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Height range (1st–99th percentile)</source>
        <translation>Intervallo di quote (1°–99° percentile)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Workspace</source>
        <translation>Area di lavoro</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images folder</source>
        <translation>Cartella delle immagini</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Coordinate reference system</source>
        <translation>Sistema di riferimento delle coordinate</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images given / aligned / not aligned</source>
        <translation>Immagini date / allineate / non allineate</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie points / image observations</source>
        <translation>Punti di legame / osservazioni in immagine</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images given</source>
        <translation>Immagini date</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Ground sample distance (median)</source>
        <translation>Risoluzione al suolo (mediana)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Area covered by tie points</source>
        <translation>Area coperta dai punti di legame</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Ground sample distance</source>
        <translation>Risoluzione al suolo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM cells on the ground (SMRF ground filter)</source>
        <translation>Celle del DSM al suolo (filtro del terreno SMRF)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DTM cells interpolated (under objects, in holes)</source>
        <translation>Celle del DTM interpolate (sotto gli oggetti, nei buchi)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Measured / interpolated cells</source>
        <translation>Celle misurate / interpolate</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Classified point cloud</source>
        <translation>Nuvola di punti classificata</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Contours</source>
        <translation>Curve di livello</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Datum</source>
        <translation>Datum</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Sigma0 (a posteriori, unit weight = 1 px)</source>
        <translation>Sigma0 (a posteriori, peso unitario = 1 px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Redundancy</source>
        <translation>Ridondanza</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Observations / points</source>
        <translation>Osservazioni / punti</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Camera position σXY / σZ (median)</source>
        <translation>Posizione della camera σXY / σZ (mediana)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie point σXY / σZ (median)</source>
        <translation>Punto di legame σXY / σZ (mediana)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie point σXY / σZ (95th percentile)</source>
        <translation>Punto di legame σXY / σZ (95° percentile)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>GeoPackage layers</source>
        <translation>Layer GeoPackage</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Computed in</source>
        <translation>Calcolato in</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ground point residuals ({})</source>
        <translation>residui dei punti a terra ({})</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Per camera</source>
        <translation>Per camera</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera centres ({}); line width ∝ shared points</source>
        <translation>centri di presa ({}); spessore delle linee ∝ punti condivisi</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera positions ({})</source>
        <translation>posizioni delle camere ({})</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean {} px</source>
        <translation>media {} px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>median {} px</source>
        <translation>mediana {} px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Per-image table</source>
        <translation>Tabella per immagine</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Screening table</source>
        <translation>Tabella del controllo</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Parameters used</source>
        <translation>Parametri usati</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>standard deviation ({})</source>
        <translation>deviazione standard ({})</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Per camera: standard deviations</source>
        <translation>Per camera: deviazioni standard</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Control points: adjusted standard deviations</source>
        <translation>Punti d'appoggio: deviazioni standard compensate</translation>
    </message>
</context>
<context>
    <name>ResultLayers</name>
    <message>
        <location filename="../qgisio/layers.py" line="327"/>
        <source>found</source>
        <translation>trovato</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="327"/>
        <source>not found</source>
        <translation>non trovato</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="851"/>
        <source>Targets found</source>
        <translation>Target trovati</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="290"/>
        <source>control (used)</source>
        <translation>appoggio (usato)</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="291"/>
        <source>check point</source>
        <translation>punto di controllo</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="292"/>
        <source>rejected (outlier)</source>
        <translation>scartato (valore anomalo)</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="293"/>
        <source>not triangulated</source>
        <translation>non triangolato</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="845"/>
        <source>DSM</source>
        <translation>DSM</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="791"/>
        <source>DSM hillshade</source>
        <translation>Ombreggiatura del DSM</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="846"/>
        <source>Orthomosaic</source>
        <translation>Ortomosaico</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="847"/>
        <source>Cameras</source>
        <translation>Camere</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="803"/>
        <source>Camera footprints</source>
        <translation>Impronte delle immagini</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="811"/>
        <source>GCP residuals (vectors x{})</source>
        <translation>Residui dei punti d'appoggio (vettori x{})</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="848"/>
        <source>Point cloud</source>
        <translation>Nuvola di punti</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="857"/>
        <source>ArchaeoOrtho: {}</source>
        <translation>ArchaeoOrtho: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="468"/>
        <source>{} ({})</source>
        <translation>{} ({})</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="849"/>
        <source>DTM</source>
        <translation>DTM</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="819"/>
        <source>DTM hillshade</source>
        <translation>Ombreggiatura del DTM</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="850"/>
        <source>Contours</source>
        <translation>Curve di livello</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="452"/>
        <source>{} — {}</source>
        <translation>{} — {}</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="408"/>
        <source>Spectral index</source>
        <translation>Indice spettrale</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="844"/>
        <source>RGB orthomosaic</source>
        <translation>Ortomosaico RGB</translation>
    </message>
    <message>
        <location filename="../qgisio/scene_layers.py" line="43"/>
        <source>3-D model</source>
        <translation>Modello 3D</translation>
    </message>
    <message>
        <location filename="../qgisio/legend.py" line="11"/>
        <source>DTM (bare earth)</source>
        <translation>DTM (terreno nudo)</translation>
    </message>
    <message>
        <location filename="../qgisio/scene_layers.py" line="111"/>
        <source>3D Tiles not loaded: {}</source>
        <translation>3D Tiles non caricati: {}</translation>
    </message>
</context>
<context>
    <name>RunPipelineAlgorithm</name>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Folder of images</source>
        <translation>Cartella delle immagini</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Workspace folder</source>
        <translation>Cartella dell'area di lavoro</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Camera positions (CSV)</source>
        <translation>Posizioni delle camere (CSV)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Pair selection</source>
        <translation>Selezione delle coppie</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Camera model</source>
        <translation>Modello di camera</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Write the accuracy report</source>
        <translation>Scrivi il rapporto di accuratezza</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="154"/>
        <source>DSM</source>
        <translation>DSM</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="155"/>
        <source>Orthomosaic</source>
        <translation>Ortomosaico</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="160"/>
        <source>Accuracy report (HTML)</source>
        <translation>Rapporto di accuratezza (HTML)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="227"/>
        <source>Seconds per stage: {}</source>
        <translation>Secondi per fase: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Run pipeline</source>
        <translation>Esegui l'intera elaborazione</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Ground control file</source>
        <translation>File dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Ground control layer</source>
        <translation>Layer dei punti d'appoggio</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Check points</source>
        <translation>Punti di controllo</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Use EXIF GPS positions</source>
        <translation>Usa le posizioni GPS EXIF</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Target CRS</source>
        <translation>SR di destinazione</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Matching image size (px)</source>
        <translation>Dimensione per la corrispondenza (px)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Refine camera calibration</source>
        <translation>Affina la calibrazione della camera</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>DSM resolution (m)</source>
        <translation>Risoluzione del DSM (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Matching quality</source>
        <translation>Qualità della corrispondenza</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Seam blending</source>
        <translation>Sfumatura delle giunzioni</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Parallel workers</source>
        <translation>Processi paralleli</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Dask scheduler</source>
        <translation>Scheduler Dask</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Build the DTM</source>
        <translation>Genera il DTM</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Contour interval (m, 0 = none)</source>
        <translation>Equidistanza (m, 0 = nessuna)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Relief visualisations</source>
        <translation>Visualizzazioni del rilievo</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="153"/>
        <source>DTM</source>
        <translation>DTM</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>GCP pixels measured on upright photos</source>
        <translation>Pixel dei GCP misurati sulle foto raddrizzate</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Sky masks (oblique photos)</source>
        <translation>Maschere del cielo (foto oblique)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Camera calibration file</source>
        <translation>File di calibrazione della camera</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Interior orientation</source>
        <translation>Orientamento interno</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Orthomosaic resolution (CRS units, 0 = GSD)</source>
        <translation>Risoluzione ortomosaico (unità SR, 0 = GSD)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Targets to find</source>
        <translation>Target da trovare</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Target kind</source>
        <translation>Tipo di target</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="185"/>
        <source>Give ground control (Ground control file or layer, or targets to find: GCPS, GCP_LAYER, TARGETS) and/or camera positions (Camera positions (CSV) or Use EXIF GPS positions: CAMERA_POSITIONS, USE_EXIF_GPS): the DSM and orthophoto need a georeferenced block</source>
        <translation>Indicare punti di appoggio (File o Layer dei punti d'appoggio, o target da trovare: GCPS, GCP_LAYER, TARGETS) e/o posizioni delle camere (Posizioni delle camere (CSV) o Usa le posizioni GPS EXIF: CAMERA_POSITIONS, USE_EXIF_GPS): DSM e ortofoto richiedono un blocco georeferenziato</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Calibration panel folder</source>
        <translation>Cartella del pannello di calibrazione</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Panel reflectance</source>
        <translation>Riflettanza del pannello</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Panel window</source>
        <translation>Finestra del pannello</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Capture radiometry</source>
        <translation>Radiometria delle acquisizioni</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="156"/>
        <source>RGB orthomosaic (a rig&apos;s RGB frames)</source>
        <translation>Ortomosaico RGB (le immagini RGB di un rig)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>The whole chain in one call, for batch use: Align images, Georeference, Build DSM, Build orthophoto and Accuracy report on one workspace. It calls the same functions as the single algorithms, and a re-run resumes (features, matches and dense pairs already computed are reused).

Folder of images: the photos; a folder of a multispectral rig&apos;s band files (Parrot Sequoia, MicaSense, DJI multispectral) is recognised, and its captures are first stacked into multi-band photos in &lt;workspace&gt;/captures (as &apos;Stack multispectral captures&apos;), which the chain then takes. Workspace folder: where every product is written.
Capture radiometry (advanced; with a band folder): as Radiometry in &apos;Stack multispectral captures&apos;: normalised (default) removes each band&apos;s dark level, corrects its vignetting from the file&apos;s model and normalises exposure time and gain to the block&apos;s; irradiance also divides by the sun sensor&apos;s irradiance for that band (values proportional to reflectance when the light changes during the flight); raw keeps the numbers as recorded. A band file lacking what the choice needs (an exposure time, a sun-sensor reading) stops the run before the alignment, naming the file. A calibration panel is corrected the same way.
Calibration panel folder and Panel reflectance (advanced, optional; with a band folder): as in &apos;Stack multispectral captures&apos;: the band files of the calibration panel&apos;s captures, in a folder of their own, and the panel&apos;s reflectance (one number, per band as Green=0.49,Red=0.50, or a CSV file); the stacked photos, and so the orthomosaic, then hold reflectance (float32). A bad panel (saturated or not uniform in its centre, another camera, a band missing, a reflectance for a band the rig lacks) stops the run before the alignment, naming the file; so does a panel given with a folder of photos that is not a band folder. Panel window (advanced): the side of the central square the panel is measured in, a fraction of the photo&apos;s short side.
Georeferencing needs ground control (a Ground control file or layer, Check points held out) and/or camera positions (a Camera positions CSV or Use EXIF GPS positions): without them the pipeline refuses, since a DSM needs a metric scale and a vertical direction. GCP pixels measured on upright photos: as in &apos;Georeference&apos; (the pixel coordinates measured on the photos shown upright by their EXIF orientation).
Targets to find (instead of a ground control file or layer): the surveyed coordinates of targets laid on the ground; after the alignment &apos;Find targets&apos; finds them on the photos and its observations are the ground control (Target kind, advanced: as in &apos;Find targets&apos;).
Camera calibration file and Interior orientation (advanced): as in &apos;Align images&apos; (a calibrated camera held fixed through the whole chain, or refined with its standard deviations).
Sky masks (oblique photos): first a &apos;Prepare images&apos; stage finds the sky and the horizon haze in each photo and masks them, so that no tie point or DSM point comes from the sky; the prepared photos are aligned (off by default: photos looking straight down need none).
Build the DTM: after the DSM, a bare-earth DTM (as &apos;Build DTM&apos;). Contour interval (advanced): contour lines of the DTM at this interval (as &apos;Contours&apos;; 0 = none). Relief visualisations (advanced): those chosen are computed from the DTM (as &apos;Relief visualisation&apos;). Both need the DTM.
The other parameters are those of the single stages (see their help); 0 means automatic.
Outputs: the DSM, the orthomosaic and the accuracy report (HTML), plus the key figures; with a band folder that also holds the rig&apos;s RGB frames, also RGB orthomosaic (a rig&apos;s RGB frames): those frames&apos; own orthomosaic, &lt;orthomosaic&gt;_rgb.tif beside the captures&apos; multi-band one (none when no RGB frame is registered).</source>
        <translation>L'intera elaborazione in una sola chiamata, per l'uso in batch: Allinea immagini, Georeferenzia, Crea DSM, Crea ortofoto e Rapporto di accuratezza su un solo spazio di lavoro. Chiama le stesse funzioni dei singoli algoritmi, e una nuova esecuzione riprende (caratteristiche, corrispondenze e coppie dense già calcolate vengono riutilizzate).

Cartella delle immagini: le foto; una cartella di file di banda di una camera multispettrale (Parrot Sequoia, MicaSense, DJI multispettrale) è riconosciuta, e le sue acquisizioni sono prima impilate in foto multibanda in &lt;workspace&gt;/captures (come 'Impila acquisizioni multispettrali'), che la catena poi prende. Cartella dell'area di lavoro: dove sono scritti tutti i prodotti.
Radiometria delle acquisizioni (avanzato; con una cartella di bande): come Radiometria in 'Impila acquisizioni multispettrali': normalizzato (predefinito) sottrae a ogni banda il suo livello di nero, ne corregge la vignettatura secondo il modello del file e normalizza tempo di esposizione e guadagno a quelli del blocco; irradianza divide inoltre per l'irradianza del sensore solare per quella banda (valori proporzionali alla riflettanza quando la luce cambia durante il volo); grezzo mantiene i valori come registrati. Un file di banda privo di ciò che la scelta richiede (un tempo di esposizione, una lettura del sensore solare) ferma l'esecuzione prima dell'allineamento, nominando il file. Un pannello di calibrazione è corretto allo stesso modo.
Cartella del pannello di calibrazione e Riflettanza del pannello (avanzato, opzionale; con una cartella di bande): come in 'Impila acquisizioni multispettrali': i file di banda delle acquisizioni del pannello di calibrazione, in una cartella a sé, e la riflettanza del pannello (un numero, per banda come Green=0.49,Red=0.50, o un file CSV); le foto impilate, e quindi l'ortomosaico, contengono allora riflettanza (float32). Un pannello non valido (saturo o non uniforme al centro, di un'altra camera, con una banda mancante, una riflettanza per una banda che il rig non ha) ferma l'esecuzione prima dell'allineamento, nominando il file; così anche un pannello dato con una cartella di foto che non è una cartella di bande. Finestra del pannello (avanzato): il lato del quadrato centrale in cui si misura il pannello, una frazione del lato corto della foto.
La georeferenziazione richiede punti di appoggio (un file o un layer dei punti d'appoggio, punti di controllo esclusi) e/o posizioni delle camere (un CSV delle posizioni delle camere o Usa le posizioni GPS EXIF): senza di essi l'elaborazione viene rifiutata, perché un DSM richiede una scala metrica e una direzione verticale. Pixel dei GCP misurati sulle foto raddrizzate: come in 'Georeferenzia' (le coordinate pixel misurate sulle foto mostrate diritte secondo il loro orientamento EXIF).
Target da trovare (invece di un file o layer dei punti d'appoggio): le coordinate rilevate dei target posati a terra; dopo l'allineamento 'Trova i target' li trova nelle foto e le sue misure sono i punti d'appoggio (Tipo di target, avanzato: come in 'Trova i target').
File di calibrazione della camera e Orientamento interno (avanzato): come in 'Allinea immagini' (una camera calibrata mantenuta fissa per tutta la catena, o affinata con le sue deviazioni standard).
Maschere del cielo (foto oblique): prima una fase 'Prepara immagini' trova il cielo e la foschia all'orizzonte in ogni foto e li maschera, perché nessun punto di legame o del DSM provenga dal cielo; si allineano le foto preparate (disattivato per impostazione predefinita: le foto nadirali non ne hanno bisogno).
Genera il DTM: dopo il DSM, un DTM del suolo nudo (come 'Genera DTM'). Equidistanza (avanzato): curve di livello del DTM con questa equidistanza (come 'Curve di livello'; 0 = nessuna). Visualizzazioni del rilievo (avanzato): quelle scelte sono calcolate dal DTM (come 'Visualizzazione del rilievo'). Entrambe richiedono il DTM.
Gli altri parametri sono quelli delle singole fasi (vedi il loro aiuto); 0 significa automatico.
Risultati: il DSM, l'ortomosaico e il rapporto di accuratezza (HTML), più le cifre principali; con una cartella di bande che contiene anche le immagini RGB del rig, anche Ortomosaico RGB (le immagini RGB di un rig): l'ortomosaico proprio di queste immagini, &lt;orthomosaic&gt;_rgb.tif accanto a quello multibanda delle acquisizioni (nessuno quando nessuna immagine RGB è registrata).</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Build the textured 3-D model</source>
        <translation>Genera il modello 3D con texture</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="161"/>
        <source>3-D model (3D Tiles)</source>
        <translation>Modello 3D (3D Tiles)</translation>
    </message>
</context>
<context>
    <name>SpectralIndexAlgorithm</name>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Input raster</source>
        <translation>Raster di ingresso</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Index</source>
        <translation>Indice</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>NDVI</source>
        <translation>NDVI</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>NDRE</source>
        <translation>NDRE</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Expression</source>
        <translation>Espressione</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>NIR band number</source>
        <translation>Numero banda NIR</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Red band number</source>
        <translation>Numero banda rossa</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Red-edge band number</source>
        <translation>Numero banda red edge</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="61"/>
        <source>Index raster</source>
        <translation>Raster dell'indice</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="62"/>
        <source>Cells with a value</source>
        <translation>Celle con un valore</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="63"/>
        <source>Lowest value</source>
        <translation>Valore minimo</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="64"/>
        <source>Highest value</source>
        <translation>Valore massimo</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="65"/>
        <source>Mean value</source>
        <translation>Valore medio</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Spectral index</source>
        <translation>Indice spettrale</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>A vegetation index of a multispectral orthomosaic or any multi-band raster (a satellite scene), to see crop marks: over a buried ditch the crop grows greener (a higher index), over a buried wall it is stressed (a lower one). NDVI is (NIR - RED) / (NIR + RED), NDRE (NIR - REDEDGE) / (NIR + REDEDGE). A cell is nodata where a band used is nodata or masked (alpha band, mask) or the denominator is zero. The raster is read in blocks, so a large one needs little memory.

Which band is NIR, red or red edge is read from the raster: the band&apos;s description (NIR, Red, Red edge / REG / RE, Green / GRE, Blue), a name or wavelength in its metadata (790 nm is NIR: red 600-690 nm, red edge 690-760 nm, NIR 760-1000 nm) or its colour interpretation; the log says which band was taken for each name and why, and a missing name lists the bands the raster has.

Input raster: the multi-band raster.
Index: NDVI, NDRE or the expression below.
Expression: a formula of the bands, by number (b1 is the first band) or by name, e.g. (b4 - b3) / (b4 + b3) or 2.5 * (NIR - RED) / (NIR + 2.4 * RED + 1); numbers, + - * / ** and parentheses, and the functions sqrt, abs, log, exp, min, max, clip(x, low, high).
NIR band number, Red band number, Red-edge band number (advanced): the band to take for that name when the raster&apos;s band names do not say it or say it wrongly; 0 reads it from the names.
Index raster: where to write the float32 Cloud-Optimized GeoTIFF (nodata -9999, the band described by the index and its formula).</source>
        <translation>Un indice di vegetazione di un ortomosaico multispettrale o di qualsiasi raster a più bande (una scena satellitare), per vedere le tracce da vegetazione (crop marks): sopra un fossato sepolto la coltura cresce più verde (un indice più alto), sopra un muro sepolto è stressata (uno più basso). NDVI è (NIR - RED) / (NIR + RED), NDRE (NIR - REDEDGE) / (NIR + REDEDGE). Una cella è nodata dove una banda usata è nodata o mascherata (banda alfa, maschera) o il denominatore è zero. Il raster è letto a blocchi, quindi uno grande richiede poca memoria.

Quale banda sia NIR, rossa o red edge è letto dal raster: dalla descrizione della banda (NIR, Red, Red edge / REG / RE, Green / GRE, Blue), da un nome o una lunghezza d'onda nei suoi metadati (790 nm è NIR: rosso 600-690 nm, red edge 690-760 nm, NIR 760-1000 nm) o dalla sua interpretazione del colore; il log dice quale banda è stata presa per ogni nome e perché, e un nome mancante elenca le bande del raster.

Raster di ingresso: il raster a più bande.
Indice: NDVI, NDRE o l'espressione qui sotto.
Espressione: una formula delle bande, per numero (b1 è la prima banda) o per nome, ad es. (b4 - b3) / (b4 + b3) o 2.5 * (NIR - RED) / (NIR + 2.4 * RED + 1); numeri, + - * / ** e parentesi, e le funzioni sqrt, abs, log, exp, min, max, clip(x, low, high).
Numero banda NIR, Numero banda rossa, Numero banda red edge (avanzati): la banda da prendere per quel nome quando i nomi delle bande del raster non la indicano o la indicano male; 0 la legge dai nomi.
Raster dell'indice: dove scrivere il GeoTIFF Cloud-Optimized float32 (nodata -9999, la banda descritta dall'indice e dalla sua formula).</translation>
    </message>
</context>
<context>
    <name>StackCapturesAlgorithm</name>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Band folder</source>
        <translation>Cartella delle bande</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Radiometry</source>
        <translation>Radiometria</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Reference band</source>
        <translation>Banda di riferimento</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="82"/>
        <source>Output folder</source>
        <translation>Cartella di uscita</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="83"/>
        <source>Photos written</source>
        <translation>Foto scritte</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="84"/>
        <source>Captures left out</source>
        <translation>Acquisizioni escluse</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Stack multispectral captures</source>
        <translation>Impila acquisizioni multispettrali</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Calibration panel folder</source>
        <translation>Cartella del pannello di calibrazione</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Panel reflectance</source>
        <translation>Riflettanza del pannello</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Panel window</source>
        <translation>Finestra del pannello</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Turns the band files of a multispectral rig (Parrot Sequoia, MicaSense RedEdge / Altum, DJI P4 Multispectral / Mavic 3M: one 16-bit TIFF per band per capture) into one multi-band photo per capture, which Align images, Run pipeline and Build orthophoto take like any photo: the orthomosaic then has every band, and Spectral index makes NDVI or NDRE of it. The files of one capture are grouped by their capture id (else rig name and time); each band is undistorted with its own lens model from its metadata, turned by its rig rotation and registered onto the reference band by phase correlation on gradients. The photo&apos;s bands are NIR, Red, Green first (QGIS shows them as a false-colour NIR-R-G view), each named with its wavelength; the capture&apos;s GPS is in its EXIF. A capture missing a band is left out and named in the log; the band folder is never written into.

Band folder: the folder of band files (the RGB camera&apos;s frames in it are not stacked).
Radiometry: normalised (default) removes each band&apos;s dark level, corrects its vignetting from the file&apos;s model and normalises exposure time and gain to the block&apos;s; irradiance also divides by the sun sensor&apos;s irradiance for that band (values proportional to reflectance when the light changes during the flight); raw keeps the numbers as recorded. A band file lacking what the choice needs (an exposure time, a sun-sensor reading) stops the run before any work, naming the file. The photo&apos;s metadata says what was done (and per band the vignetting model, dark level and scale).
Calibration panel folder (optional): the band files of the calibration panel&apos;s captures (one capture of the panel of known reflectance in every band, before and / or after the flight, as MicaSense, DJI and Parrot ask for), in a folder of their own. With it the photos hold reflectance (0..1, float32, 0 where a band does not reach) instead of 16-bit numbers: each band is scaled by the panel&apos;s reflectance over the panel&apos;s value after the same radiometry (normalised: the panel fixes each band under the light of its capture; irradiance: the sun sensor follows the light&apos;s changes during the flight); before and after panels are averaged, and a warning says when they differ by more than 3 %. The panel is measured in the centre of its photo: a centre that is saturated or not uniform (no panel there) stops the run before any work, naming the file; so do a panel of another camera, a panel capture missing a band, and a panel reflectance for a band the rig lacks. Panel files left among the band files are not stacked.
Panel reflectance: the panel&apos;s reflectance from its calibration sheet: one number for every band (0.5), per band (Green=0.49,Red=0.50,Red edge=0.50,NIR=0.49), or the path of a CSV file of rows band name or wavelength in nm, reflectance (a curve of wavelengths is interpolated at each band&apos;s centre). Needed with a calibration panel folder.
Panel window (advanced): the side of the central square the panel is measured in, a fraction of the photo&apos;s short side (default 0.25); smaller when the panel fills less of the frame.
Reference band (advanced): the band the others are registered onto; empty: the rig&apos;s reference camera.
Output folder: where the multi-band photos are written (one per capture, named after its band files without the band suffix); not the band folder.</source>
        <translation>Trasforma i file di banda di una camera multispettrale (Parrot Sequoia, MicaSense RedEdge / Altum, DJI P4 Multispectral / Mavic 3M: un TIFF a 16 bit per banda per acquisizione) in una foto multibanda per acquisizione, che Allinea immagini, Esegui pipeline e Crea ortofoto prendono come qualsiasi foto: l'ortomosaico ha allora ogni banda, e Indice spettrale ne calcola NDVI o NDRE. I file di un'acquisizione sono raggruppati per il loro ID di acquisizione (altrimenti per nome del rig e ora); ogni banda è raddrizzata con il proprio modello d'obiettivo dai suoi metadati, ruotata della sua rotazione nel rig e registrata sulla banda di riferimento per correlazione di fase sui gradienti. Le bande della foto iniziano con NIR, Rosso, Verde (QGIS le mostra come vista a falsi colori NIR-R-G), ciascuna nominata con la sua lunghezza d'onda; il GPS dell'acquisizione è nel suo EXIF. Un'acquisizione a cui manca una banda è esclusa e nominata nel registro; nella cartella delle bande non si scrive mai.

Cartella delle bande: la cartella dei file di banda (le immagini della camera RGB al suo interno non sono impilate).
Radiometria: normalizzato (predefinito) sottrae a ogni banda il suo livello di nero, ne corregge la vignettatura secondo il modello del file e normalizza tempo di esposizione e guadagno a quelli del blocco; irradianza divide inoltre per l'irradianza del sensore solare per quella banda (valori proporzionali alla riflettanza quando la luce cambia durante il volo); grezzo mantiene i valori come registrati. Un file di banda privo di ciò che la scelta richiede (un tempo di esposizione, una lettura del sensore solare) ferma l'esecuzione prima di ogni lavoro, nominando il file. I metadati della foto dicono cosa è stato fatto (e per banda il modello di vignettatura, il livello di nero e la scala).
Cartella del pannello di calibrazione (opzionale): i file di banda delle acquisizioni del pannello di calibrazione (un'acquisizione del pannello di riflettanza nota in ogni banda, prima e / o dopo il volo, come chiedono MicaSense, DJI e Parrot), in una cartella a sé. Con essa le foto contengono riflettanza (0..1, float32, 0 dove una banda non arriva) invece di valori a 16 bit: ogni banda è scalata dalla riflettanza del pannello divisa per il valore del pannello dopo la stessa radiometria (normalizzato: il pannello fissa ogni banda sotto la luce della sua acquisizione; irradianza: il sensore solare segue i cambiamenti di luce durante il volo); i pannelli di prima e di dopo sono mediati, e un avviso dice quando differiscono di più del 3 %. Il pannello è misurato al centro della sua foto: un centro saturo o non uniforme (nessun pannello lì) ferma l'esecuzione prima di ogni lavoro, nominando il file; così anche un pannello di un'altra camera, un'acquisizione del pannello a cui manca una banda e una riflettanza del pannello per una banda che il rig non ha. I file del pannello lasciati tra i file di banda non sono impilati.
Riflettanza del pannello: la riflettanza del pannello dal suo foglio di calibrazione: un numero per ogni banda (0.5), per banda (Green=0.49,Red=0.50,Red edge=0.50,NIR=0.49) o il percorso di un file CSV con righe nome della banda o lunghezza d'onda in nm, riflettanza (una curva di lunghezze d'onda è interpolata al centro di ogni banda). Necessaria con una cartella del pannello di calibrazione.
Finestra del pannello (avanzato): il lato del quadrato centrale in cui si misura il pannello, una frazione del lato corto della foto (predefinito 0.25); più piccola quando il pannello riempie meno dell'inquadratura.
Banda di riferimento (avanzato): la banda su cui sono registrate le altre; vuoto: la camera di riferimento del rig.
Cartella di uscita: dove sono scritte le foto multibanda (una per acquisizione, nominata come i suoi file di banda senza il suffisso della banda); non la cartella delle bande.</translation>
    </message>
</context>
</TS>
