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
        <translation>Kein Webbrowser geöffnet {}</translation>
    </message>
    <message>
        <location filename="../ui/workspace_menu.py" line="107"/>
        <source>Open accuracy report</source>
        <translation>Genauigkeitsbericht öffnen</translation>
    </message>
    <message>
        <location filename="../ui/workspace_menu.py" line="111"/>
        <source>Open accuracy report (none yet: run Accuracy report or Run pipeline)</source>
        <translation>Genauigkeitsbericht öffnen (noch keiner: Genauigkeitsbericht oder Gesamte Verarbeitung ausführen)</translation>
    </message>
</context>
<context>
    <name>AccuracyReportAlgorithm</name>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="72"/>
        <source>Workspace folder</source>
        <translation>Arbeitsbereich-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="80"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="81"/>
        <source>Camera precision (GeoPackage)</source>
        <translation>Genauigkeit der Kameras (GeoPackage)</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="82"/>
        <source>Tie point precision (GeoPackage)</source>
        <translation>Genauigkeit der Verknüpfungspunkte (GeoPackage)</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="83"/>
        <source>Sections skipped</source>
        <translation>Ausgelassene Abschnitte</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="100"/>
        <source>section {} skipped: {}</source>
        <translation>Abschnitt {} ausgelassen: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="102"/>
        <source>report written: {} ({} s)</source>
        <translation>Bericht geschrieben: {} ({} s)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Accuracy report</source>
        <translation>Genauigkeitsbericht</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="72"/>
        <source>Compute uncertainty</source>
        <translation>Unsicherheit berechnen</translation>
    </message>
    <message>
        <location filename="../processing_provider/accuracy_report.py" line="77"/>
        <source>Report</source>
        <translation>Bericht</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Writes one self-contained HTML report of a workspace (plots embedded, readable offline) and returns its key figures.

Sections of the report. Summary — images given / aligned / not aligned and why, image screening, cameras with their calibrated parameters and standard deviations, GSD, area, CRS, processing times and parameters. Orientation quality: reprojection errors, tie-point track lengths, image connectivity, camera positions with residuals. Georeferencing: control and check points with dX dY dZ and image residuals, residual vectors, RMSE per set, NSSDA (FGDC-STD-007.3-1998) accuracy statements at 95 % confidence, ASPRS 2014 and 2023 accuracy classes, camera-position residuals, outliers. Uncertainty: standard deviations of cameras and tie points from the bundle adjustment covariance. Products: DSM and orthomosaic previews, resolution, valid fraction. Sections whose stage has not run are skipped with a note.

Workspace folder: a workspace folder (at least aligned).
Compute uncertainty: computes the bundle adjustment covariance (seconds for hundreds of images) for the uncertainty section and writes &lt;workspace&gt;/uncertainty/cameras.gpkg and points.gpkg.
Report: the report file (default: &lt;workspace&gt;/report.html). It is written under a temporary name and renamed when complete.</source>
        <translation>Schreibt einen eigenständigen HTML-Bericht über einen Arbeitsbereich (Diagramme eingebettet, offline lesbar) und gibt seine Kennzahlen zurück.

Abschnitte des Berichts. Übersicht — gegebene / orientierte / nicht orientierte Bilder und warum, Bildprüfung, Kameras mit ihren kalibrierten Parametern und Standardabweichungen, GSD, Fläche, KBS, Rechenzeiten und Parameter. Orientierungsqualität: Rückprojektionsfehler, Längen der Verknüpfungspunkt-Spuren, Bildverbindungen, Kamerapositionen mit Residuen. Georeferenzierung: Pass- und Kontrollpunkte mit dX dY dZ und Bildresiduen, Residuenvektoren, RMSE je Gruppe, Genauigkeitsangaben nach NSSDA (FGDC-STD-007.3-1998) mit 95 % Konfidenz, ASPRS-Genauigkeitsklassen 2014 und 2023, Residuen der Kamerapositionen, Ausreißer. Unsicherheit: Standardabweichungen der Kameras und Verknüpfungspunkte aus der Kovarianz der Bündelblockausgleichung. Produkte: Vorschauen von DOM und Orthomosaik, Auflösung, Anteil gültiger Zellen. Abschnitte, deren Schritt nicht gelaufen ist, werden mit einem Hinweis ausgelassen.

Arbeitsbereich-Ordner: ein Arbeitsbereich-Ordner (mindestens orientiert).
Unsicherheit berechnen: berechnet die Kovarianz der Bündelblockausgleichung (Sekunden für Hunderte von Bildern) für den Abschnitt zur Unsicherheit und schreibt &lt;workspace&gt;/uncertainty/cameras.gpkg und points.gpkg.
Bericht: die Berichtsdatei (Vorgabe: &lt;workspace&gt;/report.html). Sie wird unter einem vorläufigen Namen geschrieben und erst umbenannt, wenn sie vollständig ist.</translation>
    </message>
</context>
<context>
    <name>AlgorithmBase</name>
    <message>
        <location filename="../processing_provider/base.py" line="269"/>
        <source>Cancelled: {}</source>
        <translation>Abgebrochen: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/base.py" line="169"/>
        <source>Outputs not styled: {}</source>
        <translation>Ausgaben nicht gestaltet: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Photogrammetry</source>
        <translation>Photogrammetrie</translation>
    </message>
    <message>
        <location filename="../processing_provider/base.py" line="331"/>
        <source>{}: cancelling (send it again to stop at once)</source>
        <translation>{}: wird abgebrochen (erneut senden, um sofort anzuhalten)</translation>
    </message>
</context>
<context>
    <name>AlignImagesAlgorithm</name>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Folder of images</source>
        <translation>Bilderordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Workspace folder</source>
        <translation>Arbeitsbereich-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Pair selection</source>
        <translation>Paarauswahl</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Camera model</source>
        <translation>Kameramodell</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>One camera for all images</source>
        <translation>Eine Kamera für alle Bilder</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="88"/>
        <source>Camera centres</source>
        <translation>Projektionszentren</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="89"/>
        <source>Registered images</source>
        <translation>Orientierte Bilder</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="90"/>
        <source>Mean reprojection error (px)</source>
        <translation>Mittlerer Rückprojektionsfehler (px)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="118"/>
        <source>Registered {} of {} images, mean reprojection error {:.3f} px, {} points</source>
        <translation>{} von {} Bildern orientiert, mittlerer Rückprojektionsfehler {:.3f} px, {} Punkte</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="125"/>
        <source>Images not registered:</source>
        <translation>Nicht orientierte Bilder:</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="132"/>
        <source>Seconds per step: {}</source>
        <translation>Sekunden je Schritt: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Align images</source>
        <translation>Bilder ausrichten</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Mapper</source>
        <translation>Rekonstruktionsverfahren</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Matching image size (px)</source>
        <translation>Bildgröße für die Zuordnung (px)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Features per image</source>
        <translation>Merkmale je Bild</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Affine-invariant features</source>
        <translation>Affin-invariante Merkmale</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Focal length (mm)</source>
        <translation>Brennweite (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Sensor width (mm)</source>
        <translation>Sensorbreite (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Retry images left out</source>
        <translation>Ausgelassene Bilder erneut versuchen</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="121"/>
        <source>Retry {} ({} features): {} image(s) left out; main block {} -&gt; {} images{}</source>
        <translation>Neuer Versuch {} ({}-Merkmale): {} Bild(er) ausgelassen; Hauptblock {} -&gt; {} Bilder{}</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="121"/>
        <source> (not better: the previous result kept)</source>
        <translation> (nicht besser: das vorige Ergebnis bleibt)</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Camera calibration file</source>
        <translation>Kamerakalibrierungsdatei</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Interior orientation</source>
        <translation>Innere Orientierung</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="130"/>
        <source>Camera {}: interior orientation {} ({})</source>
        <translation>Kamera {}: innere Orientierung {} ({})</translation>
    </message>
    <message>
        <location filename="../processing_provider/align_images.py" line="70"/>
        <source>Camera positions (CSV)</source>
        <translation>Kamerapositionen (CSV)</translation>
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
        <translation>Structure from Motion: SIFT-Merkmale, Paarauswahl, robuste Zuordnung (RANSAC), inkrementelle Rekonstruktion mit Selbstkalibrierung (Brennweite, Bildhauptpunkt, Objektivverzeichnung) und eine abschließende Bündelblockausgleichung. Das Ergebnis wird im Arbeitsbereich-Ordner gespeichert, den die folgenden Schritte (Georeferenzieren, DOM erzeugen, Orthophoto erzeugen) als Eingabe nehmen. Ein erneuter Lauf setzt fort: bereits berechnete Merkmale und Zuordnungen werden wiederverwendet.

Paarauswahl: 'auto' nimmt EXIF-GPS-Nachbarn, wenn die Bilder GPS tragen, sonst jedes Paar bis 100 Bilder und für größere Sätze ohne GPS aufeinanderfolgende Paare mit Schleifenpaaren. Kamerapositionen (CSV), optional: die Positionen der Fotos in der Datei, die Georeferenzieren liest (ein GNSS-Protokoll, für Fotos ohne EXIF-GPS), wählen die Paare und die Nachbarn der geprüften Fotos statt EXIF-GPS; sie georeferenzieren den Block nicht.
Kameramodell: 'AUTO' schätzt Brennweite, Bildhauptpunkt, k1, k2, p1, p2 (OPENCV) für Kameras mit 10 oder mehr Bildern und darunter ein einfacheres radiales Modell.
Bildgröße für die Zuordnung: die längste Seite, auf die die Bilder für die Merkmale verkleinert werden (0 = automatisch: Fotos bis 2 Megapixel unverändert, größere auf 2 Megapixel verkleinert; DOM und Orthophotos nutzen jedes Pixel). Merkmale je Bild: 0 = automatisch (etwa 4000 je Megapixel, 2048 bis 4096). Stehen beide auf 0, werden zuerst einige Fotos geprüft: wo schwache, kontrastarme Textur (gepflügte Felder) ihnen zu wenige Merkmale lässt, nimmt der erste Durchgang 8192 schwächere, wenn nötig bei bis zu doppelter Größe (das Protokoll sagt es). Affin-invariante Merkmale helfen bei Schrägaufnahmen und sind langsamer.
Brennweite und Sensorbreite: innere Orientierung, wenn EXIF fehlt (gescannter Film): die Brennweite und die Breite der langen Bildseite in Millimetern (0 = aus EXIF / unbekannt).
Kamerakalibrierungsdatei: die innere Orientierung einer kalibrierten Kamera (YAML/JSON von ArchaeoOrtho, innere Parameter von Orthority, OpenCV, COLMAP cameras.txt oder Metashape-XML); mehrere Kameras werden den Fotos über ihre Bildmuster, das Kameramodell oder die Bildgröße zugeordnet; ein Foto anderer Auflösung erhält sie skaliert. Eine Datei, die sich nicht lesen lässt, beendet den Lauf vor jeder Arbeit und nennt Datei, Zeile und Feld.
Innere Orientierung: was die Ausgleichungen an einer Kamera ändern dürfen: 'fixed' hält die gegebenen Werte durch Ausrichtung und Georeferenzierung (auch mit automatischen Passpunkten), 'refined' lässt die Georeferenzierung sie mit den Standardabweichungen der Kalibrierung als Vorinformation verbessern, 'estimated' kalibriert ausgehend von ihnen selbst. 'auto' ist 'fixed', wo eine Kalibrierung gegeben ist (die Datei oder von 'Bilder vorbereiten' entzerrte Filmscans), sonst 'estimated'; ein eigenes 'adjust' einer Kamera in der Datei geht vor. Mit 'fixed' oder 'refined' und ohne Datei sind Brennweite und Sensorbreite die gegebenen Werte. Protokoll, sfm/alignment.json und der Genauigkeitsbericht sagen je Kamera, was gehalten wurde.
Rekonstruktionsverfahren (erweitert): 'incremental' (COLMAP, Standard) oder 'global' (GLOMAP: Rotationsmittelung und globale Positionierung, bei großen Blöcken oft schneller; ein Abbruch wirkt erst, wenn es fertig ist).
Ausgelassene Bilder erneut versuchen (erweitert, an): Bilder, die die schnellen Einstellungen auslassen, oder ein in Teile zerfallener Block werden mit reicheren Merkmalen (schwächeren für kontrastarme Bilder, affinen für steile Schrägaufnahmen) und mehr Paaren erneut versucht; das Protokoll und sfm/alignment.json sagen, was erneut versucht wurde und warum.</translation>
    </message>
</context>
<context>
    <name>ArchaeoOrthoPlugin</name>
    <message>
        <location filename="../plugin.py" line="101"/>
        <source>Ground control (GCP dock)</source>
        <translation>Passpunkte (GCP-Fenster)</translation>
    </message>
    <message>
        <location filename="../plugin.py" line="105"/>
        <source>ArchaeoOrtho: pick ground control points on the map and in the photos</source>
        <translation>ArchaeoOrtho: Passpunkte auf der Karte und in den Fotos messen</translation>
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
        <translation>ArchaeoOrtho Photogrammetrie</translation>
    </message>
</context>
<context>
    <name>AutoControlAlgorithm</name>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Aligned workspace</source>
        <translation>Ausgerichteter Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Reference orthophoto</source>
        <translation>Referenz-Orthophoto</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Reference DSM</source>
        <translation>Referenz-DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Rough position</source>
        <translation>Ungefähre Lage</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>auto</source>
        <translation>automatisch</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>EXIF GPS</source>
        <translation>EXIF-GPS</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>none</source>
        <translation>keine</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="74"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="75"/>
        <source>Camera centres (world)</source>
        <translation>Projektionszentren (Welt)</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="76"/>
        <source>Automatic GCPs kept</source>
        <translation>Behaltene automatische Passpunkte</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="77"/>
        <source>Matches found</source>
        <translation>Gefundene Zuordnungen</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="133"/>
        <source>outlier left out: {}</source>
        <translation>Ausreißer ausgelassen: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Automatic control from a reference orthophoto</source>
        <translation>Automatische Passpunkte aus einem Referenz-Orthophoto</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Reference resolution for web layers (m, 0: auto)</source>
        <translation>Referenzauflösung für Weblayer (m, 0: auto)</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="62"/>
        <source>Area to fetch from web layers</source>
        <translation>Aus Weblayern abzurufender Bereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="121"/>
        <source>Reference DSM {} given without a reference orthophoto (DEM control) must be a raster file on disk; a web layer is fetched only with a reference orthophoto</source>
        <translation>Referenz-DOM {} ohne Referenz-Orthophoto (DGM-Passpunkte) muss eine Rasterdatei auf dem Datenträger sein; ein Weblayer wird nur mit einem Referenz-Orthophoto abgerufen</translation>
    </message>
    <message>
        <location filename="../processing_provider/auto_control.py" line="125"/>
        <source>A reference DSM alone (DEM control) places the block by the photos&apos; EXIF GPS: choose Rough position auto or EXIF GPS, or give a reference orthophoto as well</source>
        <translation>Ein Referenz-DOM allein (DGM-Passpunkte) platziert den Block durch das EXIF-GPS der Fotos: Ungefähre Lage automatisch oder EXIF-GPS wählen oder zusätzlich ein Referenz-Orthophoto angeben</translation>
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
        <translation>Georeferenziert einen ausgerichteten Block ohne von Hand gesetzte Passpunkte: ein vorläufiges Orthophoto des Blocks wird bei gemeinsamer Auflösung mit einem Referenz-Orthophoto (einem amtlichen Orthophoto, dem Orthomosaik eines früheren Blocks) zugeordnet, jede Zuordnung wird in den Fotos wiedergefunden und erhält ihre Höhe aus dem Referenz-DOM, und diese automatischen Passpunkte gehen in die übliche passpunktgestützte Ausgleichung ein, die die Ausreißer auslässt. Änderungen zwischen den beiden Zeitpunkten (Feldfrüchte, Autos, neue Gebäude, ein anderer Sonnenstand) werden hingenommen: was bleibt, wird genutzt, und das Protokoll nennt, wie viele Zuordnungen jeden Schritt überstanden haben.

Ausgerichteter Arbeitsbereich: der zu georeferenzierende Block (seine Fotos müssen noch dort liegen, wo die Ausrichtung sie gefunden hat).
Referenz-Orthophoto: ein beliebiges genordetes Raster, grau oder farbig, in einem beliebigen KBS (auch einem amtlichen ohne EPSG-Code); das Ergebnis ist in seinem KBS (eine geographische oder Web-Mercator-Datei: in dem der UTM-Zone ihrer Mitte). Ein Layer, der keine lokale Datei ist (WMS, XYZ, WCS, ein virtuelles Raster), wird für die Ausdehnung des Blocks nach georef/reference-ortho.tif gespeichert (ein Web-Mercator- oder geographischer im KBS des DOM, sonst in dem der UTM-Zone).
Referenz-DOM: ein DOM oder DGM, das den Block abdeckt, in beliebigem KBS und beliebiger Auflösung (auch ein DGM mit 10-30 m: jede Höhe wird nach Neigung und Rauheit des DGM an ihrer Stelle gewichtet), Höhen in Metern oder in der Einheit, die das Raster angibt (ein WCS-Layer wird nach georef/reference-dsm.tif gespeichert).
Ein Referenz-DOM allein (ohne Orthophoto, eine Rasterdatei auf dem Datenträger) genügt: der Block wird durch das EXIF-GPS der Fotos platziert, dann auf das DOM koregistriert (Verschiebung, Kippung, Wölbung: Nuth &amp; Kääb auf den Punkten des dünnen Modells), und aus dem DGM abgeleitete Passpunkte gehen in die Ausgleichung ein (georef/dem_control.json; wie Georeferenzieren mit einem Referenz-DOM allein).
Ungefähre Lage: das EXIF-GPS der Fotos, wenn mindestens zwei es tragen (automatisch), immer (EXIF-GPS) oder nie (keine: Drehung und Maßstab werden über die ganze Referenz gesucht, die dann nicht viel größer als der Block sein sollte).
Referenzauflösung: Meter je Pixel, mit denen ein Weblayer gespeichert wird (0: 0,25 m; das DOM mit der doppelten, mindestens 0,5 m). Abzurufender Bereich: die Ausdehnung, für die ein Weblayer gespeichert wird; leer: die EXIF-GPS-Positionen der Fotos mit einem Rand, sonst die Ausdehnung der anderen Referenz.
Ausgaben: die Projektionszentren im KBS der Referenz, die Zahl der automatischen Passpunkte, die die Ausgleichung behalten hat, die gefundenen Zuordnungen; georef/autocontrol.json führt jeden Kandidaten auf, mit dem Grund, warum er behalten oder verworfen wurde.</translation>
    </message>
</context>
<context>
    <name>BuildDsmAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Workspace folder (georeferenced)</source>
        <translation>Arbeitsbereich-Ordner (georeferenziert)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>DSM resolution in metres (0 = automatic)</source>
        <translation>DOM-Auflösung in Metern (0 = automatisch)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Matching quality (image scale)</source>
        <translation>Zuordnungsqualität (Bildmaßstab)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Engine</source>
        <translation>Rechenwerk</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Parallel workers (0 = one per core)</source>
        <translation>Parallele Prozesse (0 = einer je Kern)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="63"/>
        <source>Point cloud (LAS)</source>
        <translation>Punktwolke (LAS)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="66"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="67"/>
        <source>Share of DSM cells with data inside the camera centres&apos; convex hull</source>
        <translation>Anteil der DOM-Zellen mit Daten innerhalb der konvexen Hülle der Projektionszentren</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="69"/>
        <source>Stereo pairs matched</source>
        <translation>Zugeordnete Stereopaare</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="70"/>
        <source>Fused points</source>
        <translation>Verschmolzene Punkte</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="87"/>
        <source>DSM {} ({} m cells), valid fraction {}</source>
        <translation>DOM {} ({} m Zellen), Anteil gültiger Zellen {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build DSM</source>
        <translation>DOM erzeugen</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="50"/>
        <source>Dask scheduler address (empty = this computer, or $ARCHAEOORTHO_DASK_SCHEDULER)</source>
        <translation>Adresse des Dask-Schedulers (leer = dieser Rechner, oder $ARCHAEOORTHO_DASK_SCHEDULER)</translation>
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
        <translation>Dichte Bildzuordnung des georeferenzierten Blocks und ein digitales Oberflächenmodell (DOM).

Stereopaare werden aus dem dünnen Modell gewählt (gemeinsame Verknüpfungspunkte, Basis-Höhen-Verhältnis, Blickwinkel); jedes Paar wird aus den bekannten Orientierungen entzerrt und normalisiert und mit Semi-Global Matching (OpenCV SGBM) mit Links-Rechts-Prüfung zugeordnet; ein Pixel bleibt, wo mindestens zwei unabhängige Paare übereinstimmen. Die verschmolzenen Punkte werden gerastert (Median der höchsten Höhengruppe je Zelle), kleine Lücken gefüllt und große als NoData belassen.

Arbeitsbereich-Ordner: ein georeferenzierter Arbeitsbereich (zuerst 'Georeferenzieren' ausführen: ein DOM braucht einen metrischen Maßstab und eine Lotrichtung, ein nur orientierter Arbeitsbereich wird abgelehnt).
DOM-Auflösung: DOM-Zellgröße in Metern; 0 = etwa die doppelte mittlere Bodenauflösung (GSD).
Zuordnungsqualität: Bildmaßstab für die Zuordnung (voll, halb, viertel): halb ist viermal schneller als voll.
Rechenwerk: cpu (Vorgabe); cuda führt COLMAPs Patch-Match-Stereo aus, wo pycolmap mit CUDA gebaut wurde.
DOM: Cloud-Optimized GeoTIFF, float32 mit NoData (Vorgabe: &lt;workspace&gt;/dsm.tif).
Punktwolke: optionale LAS-Datei (XYZ + RGB, KBS des Arbeitsbereichs).
Dask-Scheduler (erweitert): die Stereopaare auf einem Dask-Cluster (tcp://host:8786) rechnen, dessen Worker den Pfad des Arbeitsbereichs sehen; leer = dieser Rechner (oder die Umgebungsvariable ARCHAEOORTHO_DASK_SCHEDULER).

Ein erneuter Lauf nach einem Abbruch setzt fort und verwendet die bereits zugeordneten Paare in &lt;workspace&gt;/dense/ wieder.</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dsm.py" line="61"/>
        <source>DSM</source>
        <translation>DOM</translation>
    </message>
</context>
<context>
    <name>BuildDtmAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="53"/>
        <source>Workspace folder</source>
        <translation>Arbeitsbereich-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Contour interval in metres (0 = none)</source>
        <translation>Höhenlinienabstand in Metern (0 = keine)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Ground filter slope (rise over run)</source>
        <translation>Neigung des Bodenfilters (Steigung)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Largest object radius in metres</source>
        <translation>Größter Objektradius in Metern</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>Height above ground of an object in metres</source>
        <translation>Höhe eines Objekts über dem Boden in Metern</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="70"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="71"/>
        <source>DTM source</source>
        <translation>DGM-Herkunft</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="72"/>
        <source>Classified point cloud</source>
        <translation>Klassifizierte Punktwolke</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="73"/>
        <source>Share of DSM cells on the ground</source>
        <translation>Anteil der DOM-Zellen am Boden</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="74"/>
        <source>Share of DTM cells interpolated</source>
        <translation>Anteil der interpolierten DGM-Zellen</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="97"/>
        <source>Give a workspace folder, or a DSM file and where to write the DTM</source>
        <translation>Geben Sie einen Arbeitsbereich-Ordner an, oder eine DOM-Datei und wohin das DGM geschrieben wird</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build DTM</source>
        <translation>DGM erzeugen</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="55"/>
        <source>DSM file</source>
        <translation>DOM-Datei</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="65"/>
        <source>DTM</source>
        <translation>DGM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_dtm.py" line="67"/>
        <source>Contours</source>
        <translation>Höhenlinien</translation>
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
        <translation>Ein digitales Geländemodell (nackte Erde) aus dem DOM: Gebäude, Bäume und Feldfrüchte entfernt, der Boden darunter interpoliert.

Der Bodenfilter ist SMRF (Pingel et al. 2013, der Algorithmus von PDALs filters.smrf) auf dem Raster des DOM; unter jedem entfernten Objekt ist der Boden ein Thin-Plate-Spline durch den Boden ringsum. Das DGM ist ein Cloud-Optimized GeoTIFF auf genau dem Raster des DOM; daneben sagt terrain/dtm-source.tif, welche Zellen gemessener Boden (1) und welche interpoliert (2) sind. Die Punktwolke der DOM-Stufe wird, falls sie eine geschrieben hat, mit den ASPRS-Klassen 2 (Boden) und 1 (nicht klassifiziert) nach terrain/points-classified.las kopiert.

Arbeitsbereich-Ordner: ein Arbeitsbereich mit DOM (optional, wenn eine DOM-Datei angegeben ist).
DOM-Datei: ein beliebiges DOM in einem projizierten KBS (Meter); Vorgabe: das des Arbeitsbereichs.
Höhenlinienabstand: Höhenlinien alle so viele Meter in ein GeoPackage (0 = keine).
Neigung, größter Objektradius und Höhenschwelle (erweitert): die Parameter von SMRF (die Vorgaben von PDAL).
DGM: wohin es geschrieben wird (Vorgabe: &lt;workspace&gt;/dtm.tif).
Höhenlinien: wohin die Höhenlinien geschrieben werden (Vorgabe: &lt;workspace&gt;/terrain/contours.gpkg).</translation>
    </message>
</context>
<context>
    <name>BuildModelAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Workspace folder (with a DSM)</source>
        <translation>Arbeitsbereich-Ordner (mit einem DOM)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Geometry</source>
        <translation>Geometrie</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Face budget (triangles at most)</source>
        <translation>Flächenbudget (höchstens so viele Dreiecke)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Files</source>
        <translation>Dateien</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Texture from the photos</source>
        <translation>Textur aus den Fotos</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Atlas size in pixels (a power of two)</source>
        <translation>Atlasgröße in Pixeln (eine Zweierpotenz)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="63"/>
        <source>Number of atlases at most</source>
        <translation>Höchstens so viele Atlanten</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="76"/>
        <source>Model folder</source>
        <translation>Modellordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="78"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="79"/>
        <source>Model (GLB)</source>
        <translation>Modell (GLB)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="80"/>
        <source>Model (OBJ)</source>
        <translation>Modell (OBJ)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="81"/>
        <source>3D Tiles (tileset.json)</source>
        <translation>3D Tiles (tileset.json)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="82"/>
        <source>Faces</source>
        <translation>Flächen</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="83"/>
        <source>Share of faces textured</source>
        <translation>Anteil texturierter Flächen</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="114"/>
        <source>3-D model in {}: {} faces, {:.0%} textured</source>
        <translation>3-D-Modell in {}: {} Flächen, {:.0%} texturiert</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="118"/>
        <source>{} opens in {}</source>
        <translation>{} öffnet sich in {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_model.py" line="120"/>
        <source>QGIS {} has no 3D Tiles layers (QGIS 3.34 or newer has): open {} there or in CesiumJS, or model.glb in a glTF viewer</source>
        <translation>QGIS {} hat keine 3D-Tiles-Layer (QGIS 3.34 oder neuer hat sie): {} dort oder in CesiumJS öffnen, oder model.glb in einem glTF-Betrachter</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build 3-D model</source>
        <translation>3-D-Modell erzeugen</translation>
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
        <translation>Ein texturiertes 3-D-Modell der Fundstelle. Die Oberfläche des DOM wird zu einem Dreiecksnetz innerhalb eines Flächenbudgets, jede Fläche texturiert aus dem Foto, das sie am besten sieht; geschrieben als texturiertes OBJ (+ MTL + JPEG-Atlanten), binäres glTF (GLB, Textur eingebettet), PLY der Geometrie und OGC 3D Tiles (tileset.json mit Detailstufen), alle im KBS des Arbeitsbereichs um einen lokalen Ursprung, den die Dateien nennen.

Ab QGIS 3.34 öffnen sich die 3D Tiles als Tiled-Scene-Layer in der Gruppe des Arbeitsbereichs (Ansicht &gt; 3D-Kartenansicht zeigt sie über dem Orthomosaik); in älteren QGIS nennt das Protokoll die Dateien und die Programme, die sie öffnen. Ein Block ohne Passpunkte (ein Modellrahmen) wird als OBJ / GLB / PLY in diesem Rahmen geschrieben; 3D Tiles brauchen einen georeferenzierten Block.

Arbeitsbereich-Ordner: ein georeferenzierter Arbeitsbereich mit DOM (zuerst 'DOM erzeugen' ausführen).
Geometrie: auto (die 2,5-D-Oberfläche des DOM), dsm oder points (die 3-D-Oberfläche der fusionierten dichten Punkte: noch nicht verfügbar).
Flächenbudget: die meisten Dreiecke, die das Modell haben darf.
Dateien: die zu schreibenden Formate.
Textur aus den Fotos: aus für ein graues Modell (schneller).
Atlasgröße und Anzahl der Atlanten (erweitert): die Seitenlänge der Texturbilder in Pixeln und wie viele höchstens.
Modellordner: wohin die Dateien geschrieben werden (Vorgabe: &lt;workspace&gt;/model3d; der Ordner wird als Ganzes ersetzt).</translation>
    </message>
</context>
<context>
    <name>BuildOrthophotoAlgorithm</name>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="107"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="108"/>
        <source>Share of mosaic cells with data</source>
        <translation>Anteil der Mosaikzellen mit Daten</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="109"/>
        <source>Resolution used</source>
        <translation>Verwendete Auflösung</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="110"/>
        <source>Images in the mosaic</source>
        <translation>Bilder im Mosaik</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Build orthophoto</source>
        <translation>Orthophoto erzeugen</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Georeferenced workspace</source>
        <translation>Georeferenzierter Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>DSM</source>
        <translation>DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Images</source>
        <translation>Bilder</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Seam blending</source>
        <translation>Überblendung der Nähte</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Resampling</source>
        <translation>Resampling</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Parallel tile workers</source>
        <translation>Parallele Kachel-Prozesse</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Dask scheduler</source>
        <translation>Dask-Scheduler</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="99"/>
        <source>Orthomosaic</source>
        <translation>Orthomosaik</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="102"/>
        <source>Per-image orthophotos folder</source>
        <translation>Ordner für Einzelbild-Orthophotos</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="105"/>
        <source>Seamlines</source>
        <translation>Nahtlinien</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Seamlines to follow</source>
        <translation>Zu befolgende Nahtlinien</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="136"/>
        <source>Seamlines must be a GeoPackage (.gpkg) file, got {}</source>
        <translation>Nahtlinien müssen eine GeoPackage-Datei (.gpkg) sein, erhalten: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Far-field limit (× best ground resolution, 0 = off)</source>
        <translation>Fernfeld-Grenze (× beste Bodenauflösung, 0 = aus)</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Even out vignetting and hot spot</source>
        <translation>Vignettierung und Hotspot ausgleichen</translation>
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
        <translation>Wahre Orthophotos und das Orthomosaik eines georeferenzierten Arbeitsbereichs.

Jede Zelle nimmt ihre Höhe aus dem DOM und wird über das vollständige Kameramodell (Orientierung, Brennweite, Bildhauptpunkt, Objektivverzeichnung) in die Bilder projiziert. Eine Zelle, die in einem Bild von höherer Oberfläche verdeckt ist (eine Mauer, ein Baum, ein Hügel), bleibt aus diesem Bild weg, so dass Gebäude nicht kippen und nichts doppelt erscheint; das Mosaik füllt sie aus einem Bild, das sie sieht. Jeder Teil des Mosaiks stammt aus dem Bild, das am senkrechtesten und am nächsten zu seiner Mitte darauf blickt; Nahtlinien laufen um Gebäude und Bäume; Helligkeitsunterschiede zwischen den Bildern werden ausgeglichen und Nähte überblendet.

Georeferenzierter Arbeitsbereich: ein Arbeitsbereich mit DOM (zuerst 'DOM erzeugen' ausführen) oder ein DOM angeben.
DOM: optionales Raster (z. B. ein ALS-DOM, in beliebigem KBS: wird im Lauf umprojiziert); Vorgabe ist das DOM des Arbeitsbereichs.
Bilder: eine Auswahl, z. B. 'DJI_00*.JPG', 'IMG_0012.tif, IMG_0013.tif', 'group:2' oder 'group:NIR' (eine Kameragruppe nach Nummer oder Hersteller/Modell), '!name' lässt eines weg. Leer: alle Bilder.
Auflösung: Zellgröße in KBS-Einheiten; 0 = die Bodenauflösung der Bilder.
Überblendung der Nähte: feather (Rampe über die Nähte), multiband (Laplace-Pyramide: keine sichtbare Naht in der Helligkeit und keine Geisterbilder), none (harter Schnitt).
Vignettierung und Hotspot ausgleichen: die Abdunklung zu den Ecken der Fotos, der helle Fleck gegenüber der Sonne und die Belichtung jedes Fotos werden dort gemessen, wo sich die Fotos überlappen, und entfernt; dann gleicht eine glatte Verstärkung je Foto die Nähte an, so dass Fotos verschiedener Zeitpunkte ohne Helligkeitssprung aneinanderstoßen (nur angewandt, wo die Überlappungen dadurch besser übereinstimmen; aus: ein Belichtungsfaktor je Foto).
Fernfeld-Grenze (erweitert): jedes Bild wird nur dort verwendet, wo seine Bodenauflösung innerhalb dieses Faktors seiner besten liegt; so bleibt das gedehnte Fernfeld einer Schrägaufnahme (zum Horizont hin) weg, und das Mosaik nimmt diese Zellen aus einer näheren Ansicht; Zellen, die kein Bild fein genug sieht, bleiben leer. 0 = aus (Vorgabe 3).
Orthomosaik: Cloud-Optimized GeoTIFF mit Übersichten, den Kanälen und dem Datentyp der Bilder (8/16 Bit bleiben) und einem Alphakanal (Vorgabe &lt;workspace&gt;/orthomosaic.tif).
Ordner für Einzelbild-Orthophotos: optionaler Ordner für ein wahres Orthophoto je Bild (COG).
Nahtlinien: optionales GeoPackage mit Polygonen, die das Bild nennen, aus dem jeder Teil des Mosaiks stammt (ein Polygon je Bild, sein Name im Feld 'image'); bearbeiten Sie es, um eine Naht zu verschieben.
Zu befolgende Nahtlinien: optionale bearbeitete Nahtlinien (Polygone mit dem Feld 'image', im KBS des Mosaiks): wo ein Polygon ein Bild nennt, nimmt das Mosaik dieses Bild, wo es den Boden sieht (das Protokoll sagt, wo nicht); anderswo automatische Nähte. Formen Sie ein Polygon um oder zeichnen Sie eines und nennen Sie sein Bild, um eine Naht von einem Bewuchsmerkmal oder einem fahrenden Auto wegzulegen, und starten Sie erneut.
Dask-Scheduler (erweitert): die Kacheln auf einem Dask-Cluster (tcp://host:8786) rechnen, dessen Worker den Pfad des Arbeitsbereichs sehen; leer = dieser Rechner, oder $ARCHAEOORTHO_DASK_SCHEDULER.</translation>
    </message>
    <message>
        <location filename="../processing_provider/build_orthophoto.py" line="79"/>
        <source>Resolution (CRS units, 0 = GSD)</source>
        <translation>Auflösung (KBS-Einheiten, 0 = GSD)</translation>
    </message>
</context>
<context>
    <name>Choices</name>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>auto</source>
        <translation>automatisch (auto)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>exhaustive</source>
        <translation>alle Paare (exhaustive)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>sequential</source>
        <translation>aufeinanderfolgend (sequential)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>spatial</source>
        <translation>räumlich (spatial)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>incremental</source>
        <translation>inkrementell (incremental)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>global</source>
        <translation>global</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>fixed</source>
        <translation>fest (fixed)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>refined</source>
        <translation>verfeinert (refined)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>estimated</source>
        <translation>geschätzt (estimated)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>full</source>
        <translation>voll (full)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>half</source>
        <translation>halb (half)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>quarter</source>
        <translation>Viertel (quarter)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>feather</source>
        <translation>weiche Naht (feather)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>multiband</source>
        <translation>Mehrband (multiband)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>none</source>
        <translation>keine (none)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>bilinear</source>
        <translation>bilinear</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cubic</source>
        <translation>kubisch (cubic)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>nearest</source>
        <translation>nächster Nachbar (nearest)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cross</source>
        <translation>Kreuz (cross)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dot</source>
        <translation>Punkt (dot)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ring_dot</source>
        <translation>Punkt im Ring (ring_dot)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cross_ring</source>
        <translation>Kreuz im Ring (cross_ring)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>corners</source>
        <translation>Ecken (corners)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>sides</source>
        <translation>Seitenmitten (sides)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>eight</source>
        <translation>acht (eight)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Sky-view factor</source>
        <translation>Sky-View-Faktor</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Openness (positive)</source>
        <translation>Offenheit (positiv)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Openness (negative)</source>
        <translation>Offenheit (negativ)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Simple local relief model</source>
        <translation>Einfaches lokales Reliefmodell</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Multi-scale relief model</source>
        <translation>Mehrskaliges Reliefmodell</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Multi-direction hillshade</source>
        <translation>Schummerung aus mehreren Richtungen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Local dominance</source>
        <translation>Lokale Dominanz</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>VAT (visualisation for archaeological topography, blend)</source>
        <translation>VAT (Visualisierung für archäologische Topographie, Mischung)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>raw</source>
        <translation>roh (raw)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>normalised</source>
        <translation>normalisiert (normalised)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>irradiance</source>
        <translation>Einstrahlung (irradiance)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>checkerboard</source>
        <translation>Schachbrett (checkerboard)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>circle</source>
        <translation>Kreis (circle)</translation>
    </message>
</context>
<context>
    <name>ContoursAlgorithm</name>
    <message>
        <location filename="../processing_provider/contours.py" line="30"/>
        <source>Elevation raster</source>
        <translation>Höhenraster</translation>
    </message>
    <message>
        <location filename="../processing_provider/contours.py" line="30"/>
        <source>Interval in metres</source>
        <translation>Abstand in Metern</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Contours</source>
        <translation>Höhenlinien</translation>
    </message>
    <message>
        <location filename="../processing_provider/contours.py" line="37"/>
        <source>Contour lines</source>
        <translation>Höhenlinien</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Contour lines of a DTM or DSM at a chosen interval (GDAL&apos;s contour generator) into a GeoPackage layer &apos;contours&apos; whose &apos;elevation&apos; field labels them.

Elevation raster: a DTM or DSM in a projected CRS (metres).
Interval: metres between two contour lines (e.g. 0.5).
Contours: the GeoPackage to write.</source>
        <translation>Höhenlinien eines DGM oder DOM in einem gewählten Abstand (GDALs Höhenliniengenerator) in einen GeoPackage-Layer 'contours', dessen Feld 'elevation' sie beschriftet.

Höhenraster: ein DGM oder DOM in einem projizierten KBS (Meter).
Abstand: Meter zwischen zwei Höhenlinien (z. B. 0.5).
Höhenlinien: das zu schreibende GeoPackage.</translation>
    </message>
</context>
<context>
    <name>CoreMessages</name>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>captures: {} multi-band photo(s) of {}{} in {} ({} radiometry)</source>
        <translation>Aufnahmen: {} Mehrkanal-Foto(s) aus {}{} in {} (Radiometrie {})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pipeline done</source>
        <translation>Verarbeitung fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{}: an RGB frame of a capture not stacked (a calibration panel&apos;s, or left out): not aligned</source>
        <translation>{}: ein RGB-Bild einer nicht gestapelten Aufnahme (einer Kalibrierplatte oder ausgelassen): nicht ausgerichtet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>--- stage {} ---</source>
        <translation>--- Schritt {} ---</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>prepare: {} sky mask(s), {} of {} photos kept</source>
        <translation>Vorbereiten: {} Himmelsmaske(n), {} von {} Fotos behalten</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>find targets: {} of {} targets found, {} observations</source>
        <translation>Zielmarken finden: {} von {} Zielmarken gefunden, {} Beobachtungen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>find targets: {}</source>
        <translation>Zielmarken finden: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {} ({} image(s), {} x {} px): interior orientation {}</source>
        <translation>Kamera {} ({} Bild(er), {} x {} px): innere Orientierung {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: the calibration {} gives a focal length of {} px, {} {} px ({} %); the calibration&apos;s is used: check that it is this camera&apos;s and that its units are right</source>
        <translation>Kamera {}: die Kalibrierung {} ergibt eine Brennweite von {} px, {} {} px ({} %); die der Kalibrierung wird verwendet: prüfen Sie, ob sie zu dieser Kamera gehört und ihre Einheiten stimmen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>calibration {}, {}: {}</source>
        <translation>Kalibrierung {}, {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>calibration file {}: no photo matches {}; it is not used</source>
        <translation>Kalibrierdatei {}: kein Foto passt zu {}; sie wird nicht verwendet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>not registered: {}: {}</source>
        <translation>nicht registriert: {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation round {}: matching {} pairs</source>
        <translation>Erweiterungsrunde {}: {} Paare werden zugeordnet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation round {}: {}: {}</source>
        <translation>Erweiterungsrunde {}: {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation: {} image(s) without any verified pair after round 1, not escalated further (no ground shared with the block): {}</source>
        <translation>Erweiterung: {} Bild(er) ohne verifiziertes Paar nach Runde 1, nicht weiter erweitert (kein mit dem Block gemeinsames Gelände): {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>escalation round {}: could not put {} back ({}); a re-run extracts the features of the images of this round again</source>
        <translation>Erweiterungsrunde {}: {} konnte nicht zurückgesetzt werden ({}); ein erneuter Lauf extrahiert die Merkmale der Bilder dieser Runde neu</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>features: {} images already extracted, reused</source>
        <translation>Merkmale: {} Bilder bereits extrahiert, wiederverwendet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>features: {}/{} images ({})</source>
        <translation>Merkmale: {}/{} Bilder ({})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>matching: {} of {} pairs already matched, reused</source>
        <translation>Zuordnung: {} von {} Paaren bereits zugeordnet, wiederverwendet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>matching: {}/{} pairs</source>
        <translation>Zuordnung: {}/{} Paare</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: {} {} {}x{}, {}, {} images</source>
        <translation>Kamera {}: {} {} {}x{}, {}, {} Bilder</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>joining {} components by the photos&apos; positions (fits {} m, photo spacing {} m)</source>
        <translation>{} Teilblöcke werden über die Fotopositionen verbunden (Passung {} m, Fotoabstand {} m)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>join: {}</source>
        <translation>Verbinden: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>join: registered on the joined block&apos;s points: {}</source>
        <translation>Verbinden: an den Punkten des verbundenen Blocks registriert: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: {} image(s) outside the main block of {}; trying them against the finished block with {} 2D-3D inliers (first pass: {})</source>
        <translation>Bildzuordnung: {} Bild(er) außerhalb des Hauptblocks von {}; Versuch gegen den fertigen Block mit {} 2D-3D-Inliern (erster Durchgang: {})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: {} more image(s) registered on the relaxed threshold: {}</source>
        <translation>Bildzuordnung: {} weitere(s) Bild(er) mit gelockerter Schwelle registriert: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: global SfM (rotation averaging, global positioning, bundle adjustment)</source>
        <translation>Bildzuordnung: globales SfM (Rotationsmittelung, globale Positionierung, Bündelausgleichung)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: global SfM done</source>
        <translation>Bildzuordnung: globales SfM fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: the self-calibrated focal length went from {} to {} px and {} of {} images registered; mapping again with the photos&apos; own focal length and the distortion held</source>
        <translation>Bildzuordnung: die selbstkalibrierte Brennweite ging von {} auf {} px und {} von {} Bildern wurden registriert; erneute Zuordnung mit der eigenen Brennweite der Fotos und festgehaltener Verzeichnung</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: the focal length is held at the photos&apos; own ({} px; the distortion refined only by the final adjustment): self-calibrated it drifted to {} px and registered {} of {} images, held {}</source>
        <translation>Bildzuordnung: die Brennweite wird auf der eigenen der Fotos gehalten ({} px; die Verzeichnung nur von der abschließenden Ausgleichung verfeinert): selbstkalibriert driftete sie auf {} px und registrierte {} von {} Bildern, gehalten {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: two images, mapped with the incremental mapper (the global mapper needs tracks of three or more views)</source>
        <translation>Bildzuordnung: zwei Bilder, mit dem inkrementellen Verfahren zugeordnet (das globale braucht Spuren aus drei oder mehr Ansichten)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: registered image {}</source>
        <translation>Bildzuordnung: Bild {} registriert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: continuing the block of {} images</source>
        <translation>Bildzuordnung: der Block aus {} Bildern wird fortgesetzt</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: no further image registered</source>
        <translation>Bildzuordnung: kein weiteres Bild registriert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: {} {}: left out of the block</source>
        <translation>Bildzuordnung: {} {}: aus dem Block ausgelassen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mapping: with the intrinsics held {} images registered: the self-calibrated mapping is kept</source>
        <translation>Bildzuordnung: mit festgehaltener innerer Orientierung {} Bilder registriert: die selbstkalibrierte Zuordnung bleibt</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>final bundle adjustment: {} {}: left out of the block</source>
        <translation>abschließende Bündelausgleichung: {} {}: aus dem Block ausgelassen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>masks: {} of {} images have a mask ({}): no features where they are black</source>
        <translation>Masken: {} von {} Bildern haben eine Maske ({}): keine Merkmale, wo sie schwarz sind</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>features: {} photo(s) matched on an 8-bit image of their primary band or grey ({})</source>
        <translation>Merkmale: {} Foto(s) auf einem 8-Bit-Bild ihres Hauptkanals oder in Grau zugeordnet ({})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>aligned {}/{} images, {} px</source>
        <translation>{}/{} Bilder ausgerichtet, {} px</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pair selection: {}, {} pairs for {} images</source>
        <translation>Paarauswahl: {}, {} Paare für {} Bilder</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>final bundle adjustment</source>
        <translation>abschließende Bündelausgleichung</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM tile {}/{}</source>
        <translation>DOM-Kachel {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>matching: {} pairs ({} reused from a previous run), {} s per pair, {} s per megapixel, {}</source>
        <translation>Zuordnung: {} Paare ({} aus einem früheren Lauf wiederverwendet), {} s pro Paar, {} s pro Megapixel, {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>resuming: {} of {} pairs already matched</source>
        <translation>Fortsetzung: {} von {} Paaren bereits zugeordnet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pair {} + {} skipped: {}</source>
        <translation>Paar {} + {} übersprungen: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} image(s) are in fewer than {} matched pairs and add no points of their own: {}{}</source>
        <translation>{} Bild(er) sind in weniger als {} zugeordneten Paaren und tragen keine eigenen Punkte bei: {}{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>undistorting images (COLMAP)</source>
        <translation>Bilder werden entzerrt (COLMAP)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>patch-match stereo (COLMAP, CUDA)</source>
        <translation>Patch-Match-Stereo (COLMAP, CUDA)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>stereo fusion (COLMAP)</source>
        <translation>Stereo-Fusion (COLMAP)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>pairs: {} selected from {} overlapping image pairs ({} images, quality {}, median GSD {} m, DSM resolution {} m)</source>
        <translation>Paare: {} aus {} überlappenden Bildpaaren gewählt ({} Bilder, Qualität {}, mittlere GSD {} m, DOM-Auflösung {} m)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM done</source>
        <translation>DOM fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>points: {} fused from {} images</source>
        <translation>Punkte: {} aus {} Bildern fusioniert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>removed {}, left by a killed run</source>
        <translation>{} entfernt, von einem abgebrochenen Lauf übrig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>Helmert from {} {}</source>
        <translation>Helmert aus {} {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>triangulating control points</source>
        <translation>Passpunkte werden trianguliert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>every control point has Z = {}: treated as a placeholder, not a surveyed height; the points are taken to lie near one level surface (sigma Z {} m) and the Z figures measure the departure from that level, not height accuracy</source>
        <translation>jeder Passpunkt hat Z = {}: als Platzhalter behandelt, nicht als gemessene Höhe; die Punkte gelten als nahe einer ebenen Fläche liegend (Sigma Z {} m), und die Z-Werte messen die Abweichung von dieser Ebene, nicht die Höhengenauigkeit</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control points given sigmas far finer than the block resolves at them (about {} m XY, {} m Z) - {}: honoured as given, i.e. these points are held fixed at their coordinates; if they are not exact to that level give their real accuracy (e.g. 0.01 m for RTK)</source>
        <translation>Passpunkten wurden Sigmas gegeben, die weit feiner sind, als der Block sie auflöst (etwa {} m XY, {} m Z) - {}: wie angegeben übernommen, d. h. diese Punkte werden an ihren Koordinaten festgehalten; sind sie nicht so genau, geben Sie ihre wirkliche Genauigkeit an (z. B. 0,01 m für RTK)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>estimating the accuracy of the control given without sigmas</source>
        <translation>die Genauigkeit der ohne Sigmas angegebenen Passpunkte wird geschätzt</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the control points&apos; sigma XY ({} m) is far below how well the block fits them: {} control points miss the rigid block by {} m (median, {} sigma), and the adjustment bends the block to fit them; if their coordinates are metre-level (handheld GPS, read off a map) give the file sigma columns of that size, or none: without sigmas their accuracy is estimated from the data</source>
        <translation>das Sigma XY der Passpunkte ({} m) liegt weit unter der Passung des Blocks an sie: {} Passpunkte verfehlen den starren Block um {} m (Median, {} Sigma), und die Ausgleichung verbiegt den Block, um sie zu treffen; sind ihre Koordinaten nur metergenau (Hand-GPS, aus einer Karte abgelesen), geben Sie der Datei Sigma-Spalten dieser Größe oder keine: ohne Sigmas wird ihre Genauigkeit aus den Daten geschätzt</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>updating the model</source>
        <translation>Modell wird aktualisiert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>check points</source>
        <translation>Kontrollpunkte</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>georeferencing done</source>
        <translation>Georeferenzierung fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point not usable: {}</source>
        <translation>Passpunkt nicht verwendbar: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} camera position(s) without a height (Z): they constrain X and Y only</source>
        <translation>{} Kameraposition(en) ohne Höhe (Z): sie bestimmen nur X und Y</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point {}: {} m off the Helmert fit of the others, but consistent with the adjusted block ({} sigma, image residuals up to {} px): re-admitted; the block was deformed</source>
        <translation>Passpunkt {}: {} m neben der Helmert-Passung der anderen, aber mit dem ausgeglichenen Block verträglich ({} Sigma, Bildresiduen bis {} px): wieder aufgenommen; der Block war verformt</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no CRS given for the ground control</source>
        <translation>kein KBS für die Passpunkte angegeben</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>CRS {} not recognised; assuming metric, right-handed coordinates</source>
        <translation>KBS {} nicht erkannt; metrische, rechtshändige Koordinaten angenommen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} {} is {} m off the Helmert fit of the others (threshold {} m): excluded; check its coordinates</source>
        <translation>{} {} liegt {} m neben der Helmert-Passung der anderen (Schwelle {} m): ausgeschlossen; prüfen Sie seine Koordinaten</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point {} is {} m off the Helmert fit of the others (threshold {} m): left out of the first adjustment, then re-tested against the adjusted block</source>
        <translation>Passpunkt {} liegt {} m neben der Helmert-Passung der anderen (Schwelle {} m): aus der ersten Ausgleichung ausgelassen, dann gegen den ausgeglichenen Block erneut geprüft</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no 4 control points agree with the block within {} m: either the block is deformed or several coordinates are wrong</source>
        <translation>keine 4 Passpunkte stimmen innerhalb von {} m mit dem Block überein: entweder ist der Block verformt oder mehrere Koordinaten sind falsch</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>control point {} disagrees with the others through the block ({} m): suspect, dropped from the adjustment</source>
        <translation>Passpunkt {} widerspricht den anderen über den Block ({} m): verdächtig, aus der Ausgleichung genommen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} point {}: observation at ({}, {}) lies outside image {} ({} x {} px); ignored</source>
        <translation>Punkt ({}) {}: Beobachtung bei ({}, {}) liegt außerhalb von Bild {} ({} x {} px); ignoriert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the block adjusted with the DEM control could not be co-registered again: {}</source>
        <translation>der mit der DGM-Kontrolle ausgeglichene Block konnte nicht erneut koregistriert werden: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>bundle adjustment: {} iteration(s), cost {} -&gt; {}</source>
        <translation>Bündelausgleichung: {} Iteration(en), Kosten {} -&gt; {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera(s) {}: calibrated interior orientation fixed, not refined{}</source>
        <translation>Kamera(s) {}: kalibrierte innere Orientierung festgehalten, nicht verfeinert{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera(s) {}: interior orientation refined with priors at the calibration&apos;s values (weighted by its sigmas)</source>
        <translation>Kamera(s) {}: innere Orientierung mit Vorinformation bei den Werten der Kalibrierung verfeinert (gewichtet mit ihren Sigmas)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>adjusting {} of {} tie points ({} of {} observations); the others are re-triangulated afterwards</source>
        <translation>{} von {} Verknüpfungspunkten werden ausgeglichen ({} von {} Beobachtungen); die anderen werden danach neu trianguliert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>bundle adjustment</source>
        <translation>Bündelausgleichung</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: the calibration&apos;s model {} is not the model&apos;s {}: its intrinsics follow refine_intrinsics</source>
        <translation>Kamera {}: das Modell der Kalibrierung {} ist nicht das des Modells {}: ihre innere Orientierung folgt refine_intrinsics</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera {}: only {} image(s), intrinsics kept fixed</source>
        <translation>Kamera {}: nur {} Bild(er), innere Orientierung festgehalten</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>GCP coordinates measured on upright photos: no photo of the block is stored turned (EXIF orientation 1 or none), nothing to convert</source>
        <translation>Passpunktkoordinaten auf aufrechten Fotos gemessen: kein Foto des Blocks ist gedreht gespeichert (EXIF-Ausrichtung 1 oder keine), nichts umzurechnen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>USE_EXIF_GPS is set but no image carries EXIF GPS</source>
        <translation>USE_EXIF_GPS ist gesetzt, aber kein Bild trägt EXIF-GPS</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>co-registration done</source>
        <translation>Koregistrierung fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>co-registration iteration {}: shift {}, {} m</source>
        <translation>Koregistrierung Iteration {}: Verschiebung {}, {} m</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>georeferenced</source>
        <translation>georeferenziert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reference DEM {} without ground control or camera positions: the photos&apos; EXIF GPS place the block, the DEM fixes its heights, tilt and dome</source>
        <translation>Referenz-DGM {} ohne Passpunkte oder Kamerapositionen: das EXIF-GPS der Fotos platziert den Block, das DGM bestimmt seine Höhen, Neigung und Wölbung</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>checking the reference DEM against the block</source>
        <translation>das Referenz-DGM wird gegen den Block geprüft</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: Jacobian</source>
        <translation>Kovarianz: Jacobi-Matrix</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: normal equations</source>
        <translation>Kovarianz: Normalgleichungen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: inverting the reduced system</source>
        <translation>Kovarianz: das reduzierte System wird invertiert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance: points</source>
        <translation>Kovarianz: Punkte</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>covariance done</source>
        <translation>Kovarianz fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>automatic control: point {} of {} in the photos</source>
        <translation>automatische Passpunkte: Punkt {} von {} in den Fotos</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>provisional orthophoto: projecting {}</source>
        <translation>vorläufiges Orthophoto: {} wird projiziert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>provisional orthophoto: sampling {}</source>
        <translation>vorläufiges Orthophoto: {} wird abgetastet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>first match</source>
        <translation>erste Zuordnung</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>looking for targets: {}</source>
        <translation>Suche nach Zielmarken: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} candidate(s), {} tied across photos</source>
        <translation>{} Kandidat(en), {} über Fotos verknüpft</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} target(s), {} observation(s) found</source>
        <translation>{} Zielmarke(n), {} Beobachtung(en) gefunden</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reading images</source>
        <translation>Bilder werden gelesen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>writing Cloud-Optimized GeoTIFF</source>
        <translation>Cloud-Optimized GeoTIFF wird geschrieben</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>point cloud: {} points</source>
        <translation>Punktwolke: {} Punkte</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>3-D model done</source>
        <translation>3-D-Modell fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mesh: {} faces (DSM grid reduced {} x)</source>
        <translation>Netz: {} Flächen (DOM-Raster {}-fach reduziert)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>visibility in {}</source>
        <translation>Sichtbarkeit in {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>texture from {}</source>
        <translation>Textur aus {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>3D Tiles: level {} of {}</source>
        <translation>3D Tiles: Stufe {} von {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{}: tile {}/{}</source>
        <translation>{}: Kachel {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>orthomosaic done</source>
        <translation>Orthomosaik fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no DSM given: how far planar rectification is off because of relief cannot be measured</source>
        <translation>kein DOM angegeben: wie weit die ebene Entzerrung wegen des Reliefs abweicht, kann nicht gemessen werden</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the DSM does not cover the image&apos;s ground: planar displacement not measured</source>
        <translation>das DOM deckt das Gelände des Bildes nicht ab: ebene Verschiebung nicht gemessen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>planar rectification: tile {}/{}</source>
        <translation>ebene Entzerrung: Kachel {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>mosaic planned</source>
        <translation>Mosaik geplant</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>planning the mosaic: {}/{}</source>
        <translation>Mosaik wird geplant: {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: fall-off fitted</source>
        <translation>Radiometrie: Randabfall angepasst</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: hot spot searched</source>
        <translation>Radiometrie: Hotspot gesucht</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: gain fields fitted</source>
        <translation>Radiometrie: Verstärkungsfelder angepasst</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>radiometry: sampling {}/{}</source>
        <translation>Radiometrie: Abtastung {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>camera at X {} Y {} Z {}, omega {} phi {} kappa {} deg</source>
        <translation>Kamera bei X {} Y {} Z {}, Omega {} Phi {} Kappa {} Grad</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>oriented</source>
        <translation>orientiert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the control / DSM CRS is geographic (degrees): {} is oriented and orthorectified in EPSG:{} (the UTM zone of the image), and the orthophoto is written in it</source>
        <translation>das KBS der Passpunkte / des DOM ist geografisch (Grad): {} wird in EPSG:{} (der UTM-Zone des Bildes) orientiert und entzerrt, und das Orthophoto wird darin geschrieben</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>no CRS given: coordinates are taken as they are (no CRS written)</source>
        <translation>kein KBS angegeben: die Koordinaten werden genommen, wie sie sind (kein KBS geschrieben)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>GCP observation(s) outside the {} x {} image {}: {}</source>
        <translation>Passpunktbeobachtung(en) außerhalb des {} x {} großen Bildes {}: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} orthophoto {}: {} per cell, {} % of its cells with data</source>
        <translation>{} Orthophoto {}: {} pro Zelle, {} % seiner Zellen mit Daten</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>done</source>
        <translation>fertig</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the focal length of {} is unknown (no EXIF, none given): it is estimated from the {} control points</source>
        <translation>die Brennweite von {} ist unbekannt (kein EXIF, keine angegeben): sie wird aus den {} Passpunkten geschätzt</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM {} reprojected on the fly into the working CRS</source>
        <translation>DOM {} wird während der Verarbeitung in das Arbeits-KBS umprojiziert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>captures: {}/{} stacked</source>
        <translation>Aufnahmen: {}/{} gestapelt</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>capture {} left out: {}</source>
        <translation>Aufnahme {} ausgelassen: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky: {} of {} images show sky, hidden from the alignment</source>
        <translation>Himmel: {} von {} Bildern zeigen Himmel, vor der Ausrichtung verborgen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>one photo ({}): screened on its own, with no set to compare with (only the absolute limits: clipped highlights and shadows, dynamic range); prepared as a set&apos;s photos are</source>
        <translation>ein Foto ({}): für sich allein geprüft, ohne Vergleichssatz (nur die absoluten Grenzen: überstrahlte Lichter und Schatten, Dynamikumfang); vorbereitet wie die Fotos eines Satzes</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>masks: {} polygons ({}, y {}) hide parts of {} of {} images</source>
        <translation>Masken: {} Polygone ({}, y {}) verdecken Teile von {} von {} Bildern</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>masks: {}/{}</source>
        <translation>Masken: {}/{}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>fiducials: {}/{} scans ({}: {} marks)</source>
        <translation>Rahmenmarken: {}/{} Scans ({}: {} Marken)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>resampling {}</source>
        <translation>{} wird umgetastet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>screening: {}/{} images ({})</source>
        <translation>Prüfung: {}/{} Bilder ({})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky: {}</source>
        <translation>Himmel: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky mask: {}: {} % of the photo (rows {}–{})</source>
        <translation>Himmelsmaske: {}: {} % des Fotos (Zeilen {}–{})</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>sky mask: {}: none, {}</source>
        <translation>Himmelsmaske: {}: keine, {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>screened {} images: {} flagged, {} excluded</source>
        <translation>{} Bilder geprüft: {} markiert, {} ausgeschlossen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>writing the screening record</source>
        <translation>das Prüfprotokoll wird geschrieben</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reading the sparse model</source>
        <translation>das dünne Modell wird gelesen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>report written: {}</source>
        <translation>Bericht geschrieben: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>report: {}</source>
        <translation>Bericht: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>uncertainty: bundle adjustment covariance</source>
        <translation>Unsicherheit: Kovarianz der Bündelausgleichung</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{}: block {} of {}</source>
        <translation>{}: Block {} von {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} of {} ({} x {} cells): {}</source>
        <translation>{} von {} ({} x {} Zellen): {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>contours</source>
        <translation>Höhenlinien</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM A read</source>
        <translation>DOM A gelesen</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM B warped onto the grid of DSM A</source>
        <translation>DOM B auf das Raster von DOM A umgerechnet</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>DSM difference written</source>
        <translation>DOM-Differenz geschrieben</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: interpolating under the objects</source>
        <translation>Bodenfilter: unter den Objekten wird interpoliert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: window {} m</source>
        <translation>Bodenfilter: Fenster {} m</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: tile {} of {}</source>
        <translation>Bodenfilter: Kachel {} von {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>ground filter: object {} of {}</source>
        <translation>Bodenfilter: Objekt {} von {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>relief visualisation: {}</source>
        <translation>Reliefdarstellung: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>relief visualisation: {}, tile {} of {}</source>
        <translation>Reliefdarstellung: {}, Kachel {} von {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>saving the reference {} {}: {}</source>
        <translation>Referenz {} {} wird gespeichert: {}</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reference {} saved to {} ({} % of it has data)</source>
        <translation>Referenz {} gespeichert unter {} ({} % davon mit Daten)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>reference {} {}: {} x {} m at {} m would exceed {} pixels: saved at {} m</source>
        <translation>Referenz {} {}: {} x {} m bei {} m würden {} Pixel überschreiten: gespeichert mit {} m</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>saving the reference {} {}</source>
        <translation>Referenz {} {} wird gespeichert</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>the photos are corrected as the orthophoto&apos;s (exposure, vignetting, hot spot)</source>
        <translation>die Fotos werden wie für das Orthophoto korrigiert (Belichtung, Vignettierung, Hotspot)</translation>
    </message>
    <message>
        <location filename="../qgisio/core_messages.py" line="8"/>
        <source>{} camera(s) lie far outside the block&apos;s dense points and are left out of the DSM&apos;s extent: {}{} (check their alignment)</source>
        <translation>{} Kamera(s) liegen weit außerhalb der dichten Punkte des Blocks und bleiben bei der Ausdehnung des DOM unberücksichtigt: {}{} (ihre Ausrichtung prüfen)</translation>
    </message>
</context>
<context>
    <name>DsmDifferenceAlgorithm</name>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="36"/>
        <source>Earlier DSM</source>
        <translation>Früheres DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="36"/>
        <source>Later DSM</source>
        <translation>Späteres DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="41"/>
        <source>Difference</source>
        <translation>Differenz</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="42"/>
        <source>Median difference (m)</source>
        <translation>Median der Differenz (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="43"/>
        <source>Standard deviation of the difference (m)</source>
        <translation>Standardabweichung der Differenz (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="44"/>
        <source>Cells compared</source>
        <translation>Verglichene Zellen</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="45"/>
        <source>Cells changed by more than 1 m</source>
        <translation>Um mehr als 1 m veränderte Zellen</translation>
    </message>
    <message>
        <location filename="../processing_provider/dsm_difference.py" line="55"/>
        <source>{} cells compared: median {:.3f} m, mean {:.3f} m, std {:.3f} m, 5-95 % {:.3f} .. {:.3f} m; {} cells changed by more than {:g} m</source>
        <translation>{} Zellen verglichen: Median {:.3f} m, Mittel {:.3f} m, Std.-Abw. {:.3f} m, 5-95 % {:.3f} .. {:.3f} m; {} Zellen um mehr als {:g} m verändert</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM difference</source>
        <translation>DOM-Differenz</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>The later DSM minus the earlier one, on the earlier one&apos;s grid, shows what changed between two epochs of a site (the later DSM is warped there with GDAL, bilinear, from any CRS). A cell is nodata where either DSM has none. The log gives the cells compared, the median, mean and standard deviation of the difference, its 5th and 95th percentiles and the cells that changed by more than 1 m; a median near 0 says the two epochs are registered on each other.

Earlier DSM: the DSM the difference is measured from (its grid is the output&apos;s).
Later DSM: the DSM of the other epoch (e.g. a block registered to the earlier one with Automatic control).
Difference: where to write the float32 Cloud-Optimized GeoTIFF of later minus earlier (metres).</source>
        <translation>Das spätere DOM minus das frühere, im Raster des früheren, zeigt, was sich zwischen zwei Zeitpunkten einer Fundstelle verändert hat (das spätere DOM wird dazu mit GDAL bilinear aus einem beliebigen KBS umgerechnet). Eine Zelle ist NoData, wo eines der beiden DOM keine Daten hat. Das Protokoll nennt die verglichenen Zellen, Median, Mittel und Standardabweichung der Differenz, ihr 5. und 95. Perzentil und die Zellen, die sich um mehr als 1 m verändert haben; ein Median nahe 0 zeigt, dass die beiden Zeitpunkte aufeinander registriert sind.

Früheres DOM: das DOM, von dem aus die Differenz gemessen wird (sein Raster ist das der Ausgabe).
Späteres DOM: das DOM des anderen Zeitpunkts (z. B. eines Blocks, der mit 'Automatische Passpunkte' auf den früheren registriert wurde).
Differenz: wohin das float32-Cloud-Optimized-GeoTIFF von später minus früher (Meter) geschrieben wird.</translation>
    </message>
</context>
<context>
    <name>FindTargetsAlgorithm</name>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Aligned workspace</source>
        <translation>Ausgerichteter Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Targets (surveyed coordinates)</source>
        <translation>Zielmarken (vermessene Koordinaten)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Target kind</source>
        <translation>Art der Zielmarken</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>Target size (m, 0: unknown)</source>
        <translation>Größe der Zielmarken (m, 0: unbekannt)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="71"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="72"/>
        <source>Targets found (for review)</source>
        <translation>Gefundene Zielmarken (zur Prüfung)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="73"/>
        <source>Targets found</source>
        <translation>Gefundene Zielmarken</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="74"/>
        <source>Observations found</source>
        <translation>Gefundene Messungen</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="91"/>
        <source>{} of {} targets found, {} observations; {} candidate marks, {} tied across photos</source>
        <translation>{} von {} Zielmarken gefunden, {} Messungen; {} Kandidaten, {} über Fotos hinweg verknüpft</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Find targets</source>
        <translation>Zielmarken finden</translation>
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
        <translation>Findet die vermessenen Zielmarken am Boden auf den Fotos eines ausgerichteten Blocks und schreibt ihre Messungen subpixelgenau als gcp_list.txt, die Georeferenzieren liest: ohne Klicks. Weder GPS noch ein erster Klick sind nötig: Marken werden auf jedem Foto erkannt, über die Fotos hinweg durch Triangulation im Block verknüpft, und die triangulierten Marken werden den vermessenen Koordinaten nach ihrer Form zugeordnet (eine Ähnlichkeitstransformation aus Dreiergruppen; Maßstab und Spiegelung werden gesucht; das EXIF-GPS der Fotos, wo vorhanden, engt die Suche ein); dann wird jede benannte Zielmarke in jedes Foto projiziert, und die Marke dort kommt hinzu. Codierte Zielmarken (ArUco, AprilTag) tragen ihre Namen: eine Zielmarke, die nach ihrem Code benannt ist oder auf ihn endet (12, T12, aruco_12).

Ausgerichteter Arbeitsbereich: der Block (seine Fotos müssen noch dort liegen, wo die Ausrichtung sie fand).
Zielmarken: die vermessenen Koordinaten, eine CSV-Datei 'name,x,y,z[,sigma_xy,sigma_z]' (KBS als Zeile '# crs: EPSG:xxxx' oder im Parameter KBS) oder eine OpenDroneMap-gcp_list.txt, deren Pixelspalten fehlen ('x y z name') oder teilweise vorhanden sein dürfen: wo vorhanden, sind sie Klicks, die die Marke benennen, auf die sie fallen (gegen die Konstellation geprüft; ein Klick auf die Marke einer anderen Zielmarke wird gemeldet und ausgelassen).
KBS: das KBS der Koordinaten, wenn die Datei keines nennt.
Art der Zielmarken: automatisch (Kreuze, Schachbretter, Kreise und ArUco-4x4-Marker), eine Art oder ein ArUco- / AprilTag-Wörterbuch.
Größe der Zielmarken: Seitenlänge oder Durchmesser der Zielmarke in Metern (0: unbekannt); eine Marke, deren Größe am Boden (ihre Pixel in ihrer Entfernung, über den Maßstab der Konstellation) um mehr als den Faktor 2 davon abweicht, wird ausgelassen.
Eine Zielmarke, die ein Foto nur teilweise oder verdeckt zeigt, wird ausgelassen statt geraten; eine Marke, die nicht zur vermessenen Konstellation passt, oder eine Benennung, zu der eine andere fast ebenso gut passt, wird im Protokoll gemeldet, nie zugeordnet.
Ausgaben: die Messungsdatei (standardmäßig georef/targets/gcp_list.txt im Arbeitsbereich), ein Layer der Zielmarken mit dem Gefundenen (georef/targets/targets.gpkg: Messungen, Passung, Residuum) zur Prüfung, die Anzahl gefundener Zielmarken und Messungen; georef/targets/targets.json listet jede Messung mit ihrer Güte.</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="59"/>
        <source>CRS (where the file names none)</source>
        <translation>KBS (wenn die Datei keines nennt)</translation>
    </message>
    <message>
        <location filename="../processing_provider/find_targets.py" line="68"/>
        <source>Observations file</source>
        <translation>Messungsdatei</translation>
    </message>
</context>
<context>
    <name>FolderDialog</name>
    <message>
        <location filename="../ui/folder_dialog.py" line="47"/>
        <source>The folder {} cannot be made: {}</source>
        <translation>Der Ordner {} kann nicht angelegt werden: {}</translation>
    </message>
</context>
<context>
    <name>GcpDock</name>
    <message>
        <location filename="../ui/gcp_dock.py" line="221"/>
        <source>Report</source>
        <translation>Bericht</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="222"/>
        <source>Open the workspace&apos;s accuracy report (report.html, made by Run pipeline or Accuracy report) in the web browser</source>
        <translation>Den Genauigkeitsbericht des Arbeitsbereichs (report.html, von Run pipeline oder Accuracy report erstellt) im Webbrowser öffnen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="601"/>
        <source>The workspace has no accuracy report yet: run Accuracy report (or Run pipeline)</source>
        <translation>Der Arbeitsbereich hat noch keinen Genauigkeitsbericht: Accuracy report (oder Run pipeline) ausführen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="396"/>
        <source>No web browser opened {}</source>
        <translation>Kein Webbrowser hat {} geöffnet</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="398"/>
        <source>Accuracy report: {}</source>
        <translation>Genauigkeitsbericht: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="82"/>
        <source>ArchaeoOrtho ground control</source>
        <translation>ArchaeoOrtho Passpunkte</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="99"/>
        <source>ArchaeoOrtho photos</source>
        <translation>ArchaeoOrtho Fotos</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="161"/>
        <source>Workspace:</source>
        <translation>Arbeitsbereich:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="429"/>
        <source>none open</source>
        <translation>keiner geöffnet</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="168"/>
        <source>Open a workspace folder (made by Align images)</source>
        <translation>Einen Arbeitsbereich-Ordner öffnen (von 'Bilder ausrichten' angelegt)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="170"/>
        <source>Choose a folder of photos and a workspace folder, and align the photos</source>
        <translation>Einen Fotoordner und einen Arbeitsbereich-Ordner wählen und die Fotos ausrichten</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="177"/>
        <source>Heights (Z) from:</source>
        <translation>Höhen (Z) aus:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="182"/>
        <source>A DSM or DTM raster layer (e.g. an ALS DSM): a point picked on the map takes its height from it (bilinear). Empty: type Z by hand. Only height rasters are listed (not orthophotos, hillshades or web maps).</source>
        <translation>Ein DOM- oder DGM-Rasterlayer (z. B. ein ALS-DOM): ein auf der Karte gemessener Punkt erhält seine Höhe daraus (bilinear). Leer: Z von Hand eingeben. Nur Höhenraster werden angeboten (keine Orthofotos, Schummerungen oder Webkarten).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="67"/>
        <source>Add</source>
        <translation>Hinzufügen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="198"/>
        <source>Add a ground point</source>
        <translation>Einen Passpunkt hinzufügen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="199"/>
        <source>Remove</source>
        <translation>Entfernen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="200"/>
        <source>Remove the selected ground point and its observations</source>
        <translation>Den gewählten Passpunkt mit seinen Messungen entfernen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="195"/>
        <source>Pick on map</source>
        <translation>Auf der Karte messen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="203"/>
        <source>Click on the map canvas to set X and Y of the selected point (Z from the heights layer)</source>
        <translation>In die Kartenansicht klicken, um X und Y des gewählten Punkts zu setzen (Z aus dem Höhenlayer)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="64"/>
        <source>Import</source>
        <translation>Importieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="212"/>
        <source>Export</source>
        <translation>Exportieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="230"/>
        <source>Undo</source>
        <translation>Rückgängig</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="231"/>
        <source>Redo</source>
        <translation>Wiederholen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="241"/>
        <source>Undo: {}</source>
        <translation>Rückgängig: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="243"/>
        <source>Redo: {}</source>
        <translation>Wiederholen: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="219"/>
        <source>Load results</source>
        <translation>Ergebnisse laden</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="220"/>
        <source>Add the workspace&apos;s products to the map as styled layers</source>
        <translation>Die Produkte des Arbeitsbereichs als gestaltete Layer zur Karte hinzufügen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="277"/>
        <source>Residual tolerance:</source>
        <translation>Residuen-Toleranz:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="283"/>
        <source>Residuals up to this are green, up to 3 times yellow, beyond red</source>
        <translation>Residuen bis zu diesem Wert sind grün, bis zum Dreifachen gelb, darüber rot</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="292"/>
        <source>Refine camera calibration</source>
        <translation>Kamerakalibrierung verfeinern</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="293"/>
        <source>Let the adjustment refine focal length, principal point and distortion</source>
        <translation>Die Ausgleichung Brennweite, Bildhauptpunkt und Verzeichnung verfeinern lassen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="300"/>
        <source>Georeference</source>
        <translation>Georeferenzieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="301"/>
        <source>Run the adjustment with these points (in the background)</source>
        <translation>Die Ausgleichung mit diesen Punkten ausführen (im Hintergrund)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="302"/>
        <source>Cancel</source>
        <translation>Abbrechen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="355"/>
        <source>ArchaeoOrtho</source>
        <translation>ArchaeoOrtho</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="362"/>
        <source>Open an ArchaeoOrtho workspace</source>
        <translation>Einen ArchaeoOrtho-Arbeitsbereich öffnen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="454"/>
        <source>{} photos; the block is not aligned yet: run Align images (or &apos;New from photos&apos;) to get predicted positions</source>
        <translation>{} Fotos; der Block ist noch nicht ausgerichtet: 'Bilder ausrichten' (oder 'Neu aus Fotos') ausführen, um vorhergesagte Positionen zu erhalten</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="457"/>
        <source>{} photos, {} ground points. {}</source>
        <translation>{} Fotos, {} Passpunkte. {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="283"/>
        <source>no predicted positions: {}</source>
        <translation>keine vorhergesagten Positionen: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="66"/>
        <source>Predicted positions from the georeferenced block.</source>
        <translation>Vorhergesagte Positionen aus dem georeferenzierten Block.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="66"/>
        <source>Predicted positions once a point is placed in 2 photos, and for every point once 3 points are placed.</source>
        <translation>Vorhergesagte Positionen, sobald ein Punkt in 2 Fotos gemessen ist, und für alle Punkte, sobald 3 Punkte gemessen sind.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="185"/>
        <source>Folder of photos</source>
        <translation>Fotoordner</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="191"/>
        <source>Workspace folder (new or existing)</source>
        <translation>Arbeitsbereich-Ordner (neu oder vorhanden)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="205"/>
        <source>Aligned {} of {} photos, mean reprojection error {:.2f} px</source>
        <translation>{} von {} Fotos ausgerichtet, mittlerer Rückprojektionsfehler {:.2f} px</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="212"/>
        <source>ArchaeoOrtho: align photos</source>
        <translation>ArchaeoOrtho: Fotos ausrichten</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="612"/>
        <source>CRS: {}</source>
        <translation>KBS: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="119"/>
        <source>Click on the map at the selected point&apos;s position (Esc to stop)</source>
        <translation>Auf der Karte an die Position des gewählten Punkts klicken (Esc beendet)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="183"/>
        <source>{}: X {:.3f}, Y {:.3f}, Z {:.3f} (from {})</source>
        <translation>{}: X {:.3f}, Y {:.3f}, Z {:.3f} (aus {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="186"/>
        <source>{}: X {:.3f}, Y {:.3f}. No height at this place in {}: Z left as it was</source>
        <translation>{}: X {:.3f}, Y {:.3f}. Keine Höhe an dieser Stelle in {}: Z bleibt unverändert</translation>
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
        <translation>vorhergesagt</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="420"/>
        <source>Select or add a ground point in the table, then click on it in the photo.</source>
        <translation>Einen Passpunkt in der Tabelle wählen oder hinzufügen, dann im Foto darauf klicken.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="427"/>
        <source>from the point&apos;s other observations</source>
        <translation>aus den übrigen Messungen des Punkts</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="428"/>
        <source>from the georeferenced block</source>
        <translation>aus dem georeferenzierten Block</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="429"/>
        <source>from the points already placed (similarity fit)</source>
        <translation>aus den bereits gemessenen Punkten (Ähnlichkeitstransformation)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="440"/>
        <source>Placed at x {:.2f}, y {:.2f}. Click to move it, drag it, or press Delete to remove it.</source>
        <translation>Gemessen bei x {:.2f}, y {:.2f}. Klicken zum Versetzen, ziehen oder Entf zum Entfernen.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="443"/>
        <source>Predicted {}. Press Enter to accept it and go on (Space: accept), drag it, or click where the point really is.</source>
        <translation>Vorhergesagt {}. Eingabetaste übernimmt und geht weiter (Leertaste: übernehmen), ziehen oder dorthin klicken, wo der Punkt wirklich ist.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="455"/>
        <source>Click where {} is in this photo.</source>
        <translation>Dorthin klicken, wo {} in diesem Foto ist.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="475"/>
        <source>Select or add a ground point first</source>
        <translation>Zuerst einen Passpunkt wählen oder hinzufügen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="522"/>
        <source>{}: every photo predicted to see it has an observation</source>
        <translation>{}: jedes Foto, das ihn voraussichtlich zeigt, hat eine Messung</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="130"/>
        <source>Import ground control</source>
        <translation>Passpunkte importieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="32"/>
        <source>Ground control (*.txt *.csv);;All files (*)</source>
        <translation>Passpunkte (*.txt *.csv);;Alle Dateien (*)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="60"/>
        <source>Replace the current points, or add the imported ones to them (same names are updated)?</source>
        <translation>Die vorhandenen Punkte ersetzen oder die importierten hinzufügen (gleichnamige werden aktualisiert)?</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="64"/>
        <source>Replace</source>
        <translation>Ersetzen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="106"/>
        <source>import {}</source>
        <translation>{} importieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="107"/>
        <source>warnings</source>
        <translation>Warnungen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="114"/>
        <source>Imported {} points and {} observations from {}</source>
        <translation>{} Punkte und {} Messungen aus {} importiert</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="127"/>
        <source>No point layer in the project</source>
        <translation>Kein Punktlayer im Projekt</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="130"/>
        <source>Point layer (one feature per observation: name, image, px, py)</source>
        <translation>Punktlayer (ein Objekt je Messung: name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="145"/>
        <source>Layer {} lacks the field &apos;{}&apos; (needs name, image, px, py)</source>
        <translation>Dem Layer {} fehlt das Feld '{}' (benötigt name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="172"/>
        <source>OpenDroneMap gcp_list (*.txt)</source>
        <translation>OpenDroneMap gcp_list (*.txt)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="172"/>
        <source>CSV points + observations (*.csv)</source>
        <translation>CSV-Punkte + Messungen (*.csv)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="173"/>
        <source>Export ground control</source>
        <translation>Passpunkte exportieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="184"/>
        <source>The points have no CRS yet: pick one on the map or import a file first</source>
        <translation>Die Punkte haben noch kein KBS: zuerst einen auf der Karte messen oder eine Datei importieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="193"/>
        <source>Exported {} points to {}</source>
        <translation>{} Punkte nach {} exportiert</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="193"/>
        <source> ({} without coordinates left out)</source>
        <translation> ({} ohne Koordinaten ausgelassen)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="198"/>
        <source>Export ground control as a layer</source>
        <translation>Passpunkte als Layer exportieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="198"/>
        <source>GeoPackage (*.gpkg)</source>
        <translation>GeoPackage (*.gpkg)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="231"/>
        <source>Cannot write {}: {}</source>
        <translation>{} kann nicht geschrieben werden: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="234"/>
        <source>Exported {} observations to {}</source>
        <translation>{} Messungen nach {} exportiert</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="234"/>
        <source> (points without observations left out: {})</source>
        <translation> (Punkte ohne Messungen ausgelassen: {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="238"/>
        <source>GCP observations</source>
        <translation>Passpunktmessungen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="240"/>
        <source>Cannot add {} to the project</source>
        <translation>{} kann nicht zum Projekt hinzugefügt werden</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="224"/>
        <source>A task of this dock is still running</source>
        <translation>Eine Aufgabe dieses Fensters läuft noch</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="247"/>
        <source>Cancelled</source>
        <translation>Abgebrochen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="263"/>
        <source>The block is not aligned yet: run Align images first</source>
        <translation>Der Block ist noch nicht ausgerichtet: zuerst 'Bilder ausrichten' ausführen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="269"/>
        <source>The adjustment needs at least 3 control points with coordinates and observations; there are {}</source>
        <translation>Die Ausgleichung braucht mindestens 3 Passpunkte mit Koordinaten und Messungen; vorhanden sind {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="287"/>
        <source>Outliers left out: {}</source>
        <translation>Ausreißer ausgelassen: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="288"/>
        <source>Georeferenced in {}.</source>
        <translation>Georeferenziert in {}.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="292"/>
        <source>ArchaeoOrtho: georeference</source>
        <translation>ArchaeoOrtho: georeferenzieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="301"/>
        <source>Not georeferenced yet.</source>
        <translation>Noch nicht georeferenziert.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="303"/>
        <source>Control: RMSE XY {} m, Z {} m (n = {})</source>
        <translation>Passpunkte: RMSE XY {} m, Z {} m (n = {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="306"/>
        <source>Check: RMSE XY {} m, Z {} m (n = {})</source>
        <translation>Kontrollpunkte: RMSE XY {} m, Z {} m (n = {})</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="309"/>
        <source>heights are placeholders: no vertical accuracy</source>
        <translation>Höhen sind Platzhalter: keine Höhengenauigkeit</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="311"/>
        <source>tie points {} px</source>
        <translation>Verknüpfungspunkte {} px</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="313"/>
        <source>edited since: re-run to update</source>
        <translation>seither bearbeitet: erneut ausführen zum Aktualisieren</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="430"/>
        <source>by matching its look in another photo</source>
        <translation>durch Abgleich mit seinem Aussehen in einem anderen Foto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="434"/>
        <source>(correlation {:.2f}, {:.0f} px from the geometric prediction)</source>
        <translation>(Korrelation {:.2f}, {:.0f} px von der geometrischen Vorhersage)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="167"/>
        <source>Open…</source>
        <translation>Öffnen…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="169"/>
        <source>New from photos…</source>
        <translation>Neu aus Fotos…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="206"/>
        <source>From file (gcp_list.txt, CSV)…</source>
        <translation>Aus Datei (gcp_list.txt, CSV)…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="207"/>
        <source>From a point layer…</source>
        <translation>Aus einem Punktlayer…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="210"/>
        <source>To file (gcp_list.txt, CSV)…</source>
        <translation>In Datei (gcp_list.txt, CSV)…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="211"/>
        <source>To a GeoPackage layer…</source>
        <translation>In einen GeoPackage-Layer…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="255"/>
        <source>Cancelling…</source>
        <translation>Wird abgebrochen…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="295"/>
        <source>Georeferencing with {} control points…</source>
        <translation>Georeferenzierung mit {} Passpunkten…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="60"/>
        <source>How were the pixel coordinates measured?</source>
        <translation>Wie wurden die Pixelkoordinaten gemessen?</translation>
    </message>
    <message>
        <location filename="../ui/gcp_io.py" line="71"/>
        <source>Coordinates measured on upright photos ({} photos are stored turned: EXIF orientation); leave unticked for the stored pixel grid (COLMAP&apos;s, OpenDroneMap&apos;s)</source>
        <translation>Koordinaten auf aufrecht gedrehten Fotos gemessen ({} Fotos sind gedreht gespeichert: EXIF-Ausrichtung); nicht ankreuzen für das gespeicherte Pixelraster (das von COLMAP und OpenDroneMap)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="75"/>
        <source>your setting</source>
        <translation>Ihre Einstellung</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="78"/>
        <source>default: 3 × GSD of the georeferenced block (GSD {:.3f} m)</source>
        <translation>Vorgabe: 3 × Bodenauflösung des georeferenzierten Blocks (GSD {:.3f} m)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="79"/>
        <source>default</source>
        <translation>Vorgabe</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="86"/>
        <source>Residuals up to this are green, up to 3 times yellow, beyond red. Now: {}</source>
        <translation>Residuen bis zu diesem Wert sind grün, bis zum Dreifachen gelb, darüber rot. Jetzt: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="96"/>
        <source>Diagnosis of the adjustment:</source>
        <translation>Diagnose der Ausgleichung:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="174"/>
        <source>Moved {:.2f} m (Undo: Ctrl+Z).</source>
        <translation>Um {:.2f} m verschoben (Rückgängig: Strg+Z).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="397"/>
        <source>near the edge</source>
        <translation>nahe am Rand</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="446"/>
        <source>{} is predicted where it cannot be placed: {}. Click where the point is if you see it, or press Enter for the next photo.</source>
        <translation>{} wird dort vorhergesagt, wo er nicht gesetzt werden kann: {}. Klicken Sie auf den Punkt, wenn Sie ihn sehen, oder drücken Sie die Eingabetaste für das nächste Foto.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="452"/>
        <source>Click where {} is in this photo, or use Pick on map (or type X, Y, Z in the table) to have it predicted in the photos.</source>
        <translation>Klicken Sie in diesem Foto auf {}, oder nutzen Sie „Auf der Karte messen“ (oder geben Sie X, Y, Z in der Tabelle ein), damit er in den Fotos vorhergesagt wird.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="465"/>
        <source>{}: the workspace has no photos to place it in.</source>
        <translation>{}: der Arbeitsbereich hat keine Fotos, in denen er gesetzt werden kann.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="467"/>
        <source>{} is selected: use Pick on map or type X, Y, Z in the table, or choose a photo in the strip below and click on the point.</source>
        <translation>{} ist ausgewählt: nutzen Sie „Auf der Karte messen“ oder geben Sie X, Y, Z in der Tabelle ein, oder wählen Sie unten ein Foto und klicken Sie auf den Punkt.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="469"/>
        <source>{} is selected: choose a photo in the strip below and click on the point.</source>
        <translation>{} ist ausgewählt: wählen Sie unten ein Foto und klicken Sie auf den Punkt.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="238"/>
        <source>Undo (Ctrl+Z)</source>
        <translation>Rückgängig (Strg+Z)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="238"/>
        <source>Redo (Ctrl+Shift+Z)</source>
        <translation>Wiederholen (Strg+Umschalt+Z)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="475"/>
        <source>Aligned {} of {} photos, mean reprojection error {:.2f} px.</source>
        <translation>{} von {} Fotos ausgerichtet, mittlerer Rückprojektionsfehler {:.2f} px.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="480"/>
        <source>Not aligned ({}): {}</source>
        <translation>Nicht ausgerichtet ({}): {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="481"/>
        <source>(marked in the photo strip; hover for the reason)</source>
        <translation>(in der Fotoleiste markiert; der Grund steht im Tooltip)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="510"/>
        <source>✗ not aligned</source>
        <translation>✗ nicht ausgerichtet</translation>
    </message>
    <message>
        <location filename="../ui/gcp_dock.py" line="511"/>
        <source>{}: not aligned: {}</source>
        <translation>{}: nicht ausgerichtet: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="208"/>
        <source>Not aligned: {}</source>
        <translation>Nicht ausgerichtet: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="141"/>
        <source>pick on map</source>
        <translation>auf der Karte messen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="432"/>
        <source>(no Z yet: at the height of the block&apos;s tie points)</source>
        <translation>(noch kein Z: auf der Höhe der Verknüpfungspunkte des Blocks)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="166"/>
        <source>{} not moved</source>
        <translation>{} nicht verschoben</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="195"/>
        <source>{} is placed in {} photos. Move it {:.2f} m to the picked position, or add a new point there?</source>
        <translation>{} ist in {} Fotos gesetzt. Um {:.2f} m an die gemessene Position verschieben, oder dort einen neuen Punkt anlegen?</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="199"/>
        <source>Move {}</source>
        <translation>{} verschieben</translation>
    </message>
    <message>
        <location filename="../ui/gcp_placement.py" line="200"/>
        <source>New point</source>
        <translation>Neuer Punkt</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="157"/>
        <source>ArchaeoOrtho: refine {} in {}</source>
        <translation>ArchaeoOrtho: {} in {} verfeinern</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="327"/>
        <source>Results loaded</source>
        <translation>Ergebnisse geladen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="334"/>
        <source>ArchaeoOrtho: load results</source>
        <translation>ArchaeoOrtho: Ergebnisse laden</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="336"/>
        <source>Loading the results…</source>
        <translation>Die Ergebnisse werden geladen…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="111"/>
        <source>ArchaeoOrtho: open workspace</source>
        <translation>ArchaeoOrtho: Arbeitsbereich öffnen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="113"/>
        <source>Opening {}…</source>
        <translation>{} wird geöffnet…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="49"/>
        <source>Automatic control from a reference orthophoto</source>
        <translation>Automatisch aus Referenz-Orthophoto</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="52"/>
        <source>Georeference with no hand-picked GCP: the block is matched to a reference orthophoto and takes its heights from a reference DSM. The points of the table become check points.</source>
        <translation>Georeferenzieren ohne von Hand gesetzte Passpunkte: der Block wird einem Referenz-Orthophoto zugeordnet und nimmt seine Höhen aus einem Referenz-DOM. Die Punkte der Tabelle werden Kontrollpunkte.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="58"/>
        <source>A reference orthophoto: a raster file, or a WMS / XYZ layer (saved for the block&apos;s extent, from the photos&apos; GPS or the map extent)</source>
        <translation>Ein Referenz-Orthophoto: eine Rasterdatei oder ein WMS-/XYZ-Layer (für die Ausdehnung des Blocks gespeichert, aus dem GPS der Fotos oder der Kartenausdehnung)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="58"/>
        <source>A reference DSM or DTM (heights in metres): a raster file or a WCS layer. Only height rasters are listed: not orthophotos, hillshades, web maps or this workspace&apos;s own products</source>
        <translation>Ein Referenz-DOM oder -DGM (Höhen in Metern): eine Rasterdatei oder ein WCS-Layer. Nur Höhenraster werden angeboten: keine Orthofotos, Schummerungen, Webkarten oder eigenen Produkte dieses Arbeitsbereichs</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="69"/>
        <source>Reference orthophoto:</source>
        <translation>Referenz-Orthophoto:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="70"/>
        <source>Reference DSM:</source>
        <translation>Referenz-DOM:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="116"/>
        <source>Georeference from the reference orthophoto and DSM (in the background)</source>
        <translation>Aus Referenz-Orthophoto und -DOM georeferenzieren (im Hintergrund)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="137"/>
        <source>Automatic control: choose a reference orthophoto and a reference DSM layer</source>
        <translation>Automatische Passpunkte: ein Referenz-Orthophoto und einen Referenz-DOM-Layer wählen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="158"/>
        <source>Automatic control: {} automatic GCPs kept of {} matches; georeferenced in {}.</source>
        <translation>Automatische Passpunkte: {} automatische Passpunkte von {} Zuordnungen behalten; georeferenziert in {}.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="161"/>
        <source>Check points: RMSE XY {:.3f} m, Z {:.3f} m (n = {}).</source>
        <translation>Kontrollpunkte: RMSE XY {:.3f} m, Z {:.3f} m (n = {}).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="172"/>
        <source>ArchaeoOrtho: automatic control</source>
        <translation>ArchaeoOrtho: automatische Passpunkte</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="176"/>
        <source>Automatic control against {} and {}…</source>
        <translation>Automatische Passpunkte gegen {} und {}…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="188"/>
        <source>Automatic GCPs (residuals)</source>
        <translation>Automatische Passpunkte (Residuen)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="66"/>
        <source>found by Find targets ({}), quality {:.2f}</source>
        <translation>von Zielmarken finden gefunden ({}), Güte {:.2f}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="69"/>
        <source>, {:.2f} px from the other photos&apos; rays</source>
        <translation>, {:.2f} px von den Strahlen der anderen Fotos</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="80"/>
        <source>Find targets</source>
        <translation>Zielmarken finden</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="86"/>
        <source>Surveyed coordinates (*.csv *.txt);;All files (*)</source>
        <translation>Vermessene Koordinaten (*.csv *.txt);;Alle Dateien (*)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="87"/>
        <source>A CSV name,x,y,z[,sigma_xy,sigma_z] or an ODM gcp_list.txt (its pixel columns may be absent)</source>
        <translation>Eine CSV-Datei name,x,y,z[,sigma_xy,sigma_z] oder eine ODM-gcp_list.txt (ihre Pixelspalten dürfen fehlen)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="89"/>
        <source>Surveyed coordinates:</source>
        <translation>Vermessene Koordinaten:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="93"/>
        <source>auto (crosses, checkerboards, circles, ArUco 4x4)</source>
        <translation>automatisch (Kreuze, Schachbretter, Kreise, ArUco 4x4)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="95"/>
        <source>Target kind:</source>
        <translation>Art der Zielmarken:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="100"/>
        <source>unknown</source>
        <translation>unbekannt</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="101"/>
        <source>The target&apos;s side or diameter: marks of another size are left out</source>
        <translation>Seitenlänge oder Durchmesser der Zielmarke: Marken anderer Größe werden ausgelassen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="102"/>
        <source>Target size:</source>
        <translation>Größe der Zielmarken:</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="104"/>
        <source>A file that names no CRS is read in {}.</source>
        <translation>Eine Datei, die kein KBS nennt, wird in {} gelesen.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="104"/>
        <source>The file must name its CRS (the table and the workspace have none).</source>
        <translation>Die Datei muss ihr KBS nennen (Tabelle und Arbeitsbereich haben keines).</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="157"/>
        <source>Find targets on the photos…</source>
        <translation>Zielmarken auf den Fotos finden…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="158"/>
        <source>Find the surveyed targets on the aligned photos (in the background): their observations fill the table, marked as found until you confirm them (Space or Enter) or reject them (Delete or R)</source>
        <translation>Die vermessenen Zielmarken auf den ausgerichteten Fotos finden (im Hintergrund): ihre Messungen füllen die Tabelle, als gefunden markiert, bis Sie sie übernehmen (Leertaste oder Eingabe) oder verwerfen (Entf oder R)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="209"/>
        <source>ArchaeoOrtho: find targets</source>
        <translation>ArchaeoOrtho: Zielmarken finden</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="211"/>
        <source>Looking for the targets of {} on the photos…</source>
        <translation>Die Zielmarken aus {} werden auf den Fotos gesucht…</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="237"/>
        <source>find targets</source>
        <translation>Zielmarken finden</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="239"/>
        <source>Find targets: {} of {} targets found, {} observations, in {:.0f} s.</source>
        <translation>Zielmarken finden: {} von {} Zielmarken gefunden, {} Messungen, in {:.0f} s.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="244"/>
        <source>not found: {}</source>
        <translation>nicht gefunden: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="316"/>
        <source>Every found observation is confirmed or rejected</source>
        <translation>Jede gefundene Messung ist übernommen oder verworfen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="356"/>
        <source>{} observations found by Find targets, not confirmed: {}</source>
        <translation>{} Messungen von Zielmarken finden gefunden, nicht übernommen: {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="367"/>
        <source>{} found observations are not confirmed yet: they are used as they are (reject the wrong ones first)</source>
        <translation>{} gefundene Messungen sind noch nicht übernommen: sie werden so verwendet, wie sie sind (verwerfen Sie zuerst die falschen)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="216"/>
        <source>{} (automatic)</source>
        <translation>{} (automatisch)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="218"/>
        <source>Automatic GCP: measured by the automatic control (matched against the reference orthophoto)</source>
        <translation>Automatischer Passpunkt: von der automatischen Passpunktsuche gemessen (mit dem Referenz-Orthofoto abgeglichen)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="221"/>
        <source>&lt;b&gt;{}&lt;/b&gt; (automatic GCP) — {}</source>
        <translation>&lt;b&gt;{}&lt;/b&gt; (automatischer Passpunkt) — {}</translation>
    </message>
    <message>
        <location filename="../ui/gcp_autocontrol.py" line="222"/>
        <source>{} is an automatic GCP: found by the automatic control at x {:.2f}, y {:.2f} in this photo (measured in {} photos), not a prediction to place. Drag it to correct it, or press Delete to remove it from this photo.</source>
        <translation>{} ist ein automatischer Passpunkt: von der automatischen Passpunktsuche bei x {:.2f}, y {:.2f} in diesem Foto gefunden (in {} Fotos gemessen), keine zu platzierende Vorhersage. Zum Korrigieren ziehen oder mit Entf aus diesem Foto entfernen.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="249"/>
        <source>Space or Enter: confirm the found observation shown; Delete or R: reject it (the keys work in the table, which has the keyboard focus now, and in the photo view). Georeference uses the found observations that are not rejected, confirmed or not.</source>
        <translation>Leertaste oder Eingabe: die gezeigte gefundene Beobachtung bestätigen; Entf oder R: sie verwerfen (die Tasten wirken in der Tabelle, die jetzt den Tastaturfokus hat, und in der Fotoansicht). Georeferenzieren verwendet die gefundenen Beobachtungen, die nicht verworfen sind, bestätigt oder nicht.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_targets.py" line="332"/>
        <source>Found by Find targets, not confirmed: Space or Enter confirms it, Delete or R rejects it (then the next one); the keys work in the table and in this photo view.</source>
        <translation>Von Zielmarken finden gefunden, nicht bestätigt: Leertaste oder Eingabe bestätigt, Entf oder R verwirft (dann die nächste); die Tasten wirken in der Tabelle und in dieser Fotoansicht.</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="121"/>
        <source>{} has new results: open it once this dock&apos;s task has ended</source>
        <translation>{} hat neue Ergebnisse: öffnen Sie ihn, sobald die Aufgabe dieses Docks beendet ist</translation>
    </message>
    <message>
        <location filename="../ui/gcp_tasks.py" line="218"/>
        <source>Aligning the photos of {} into {}…</source>
        <translation>Die Fotos von {} werden in {} ausgerichtet…</translation>
    </message>
</context>
<context>
    <name>GcpStore</name>
    <message>
        <location filename="../ui/store.py" line="316"/>
        <source>a point named {} exists already</source>
        <translation>ein Punkt namens {} existiert bereits</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="304"/>
        <source>add point {}</source>
        <translation>Punkt {} hinzufügen</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="311"/>
        <source>remove point {}</source>
        <translation>Punkt {} entfernen</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="329"/>
        <source>set {} of {}</source>
        <translation>{} von {} setzen</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="389"/>
        <source>place {} in {}</source>
        <translation>{} in {} messen</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="397"/>
        <source>remove {} from {}</source>
        <translation>{} aus {} entfernen</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="538"/>
        <source>set CRS</source>
        <translation>KBS setzen</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="357"/>
        <source>no position</source>
        <translation>keine Position</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="362"/>
        <source>({:.0f}, {:.0f}) is outside the photo {} ({} × {} px)</source>
        <translation>({:.0f}, {:.0f}) liegt außerhalb des Fotos {} ({} × {} px)</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="369"/>
        <source>({:.0f}, {:.0f}) is inside the mask of {}</source>
        <translation>({:.0f}, {:.0f}) liegt in der Maske von {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="377"/>
        <source>{} not placed: {}</source>
        <translation>{} nicht gesetzt: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="429"/>
        <source>{} points replaced by {} from the file</source>
        <translation>{} Punkte durch {} aus der Datei ersetzt</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="463"/>
        <source>added {} points: {}</source>
        <translation>{} Punkte hinzugefügt: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="465"/>
        <source>coordinates updated from the file: {}</source>
        <translation>Koordinaten aus der Datei aktualisiert: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="467"/>
        <source>role set by the file: {}</source>
        <translation>Rolle von der Datei gesetzt: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="469"/>
        <source>role kept (the file gives none): {}</source>
        <translation>Rolle beibehalten (die Datei nennt keine): {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="471"/>
        <source>σ set by the file: {}</source>
        <translation>σ von der Datei gesetzt: {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="473"/>
        <source>{} observations added</source>
        <translation>{} Messungen hinzugefügt</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="475"/>
        <source>placed observations kept (the file has others): {}</source>
        <translation>gesetzte Messungen beibehalten (die Datei hat andere): {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="477"/>
        <source>nothing changed</source>
        <translation>nichts geändert</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="486"/>
        <source>observations placed by hand kept (found ones not used there): {}</source>
        <translation>von Hand gesetzte Messungen beibehalten (gefundene dort nicht verwendet): {}</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="526"/>
        <source>confirm {} in {}</source>
        <translation>{} in {} übernehmen</translation>
    </message>
    <message>
        <location filename="../ui/store.py" line="535"/>
        <source>reject {} in {}</source>
        <translation>{} in {} verwerfen</translation>
    </message>
</context>
<context>
    <name>GcpTableModel</name>
    <message>
        <location filename="../ui/gcp_table.py" line="37"/>
        <source>Name</source>
        <translation>Name</translation>
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
        <translation>Rolle</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="38"/>
        <source>Obs.</source>
        <translation>Mess.</translation>
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
        <translation>Kontrolle</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="41"/>
        <source>control</source>
        <translation>Passpunkt</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="53"/>
        <source>Horizontal residual after the adjustment (estimated from the photos minus given)</source>
        <translation>Lageresiduum nach der Ausgleichung (aus den Fotos geschätzt minus gegeben)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="54"/>
        <source>Vertical residual after the adjustment</source>
        <translation>Höhenresiduum nach der Ausgleichung</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="55"/>
        <source>Mean reprojection error of the point&apos;s observations (pixels)</source>
        <translation>Mittlerer Rückprojektionsfehler der Messungen des Punkts (Pixel)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="56"/>
        <source>Number of photos the point is placed in</source>
        <translation>Anzahl der Fotos, in denen der Punkt gemessen ist</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="69"/>
        <source>rejected as an outlier</source>
        <translation>als Ausreißer verworfen</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="71"/>
        <source>not triangulated (fewer than 2 usable observations)</source>
        <translation>nicht trianguliert (weniger als 2 brauchbare Messungen)</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="77"/>
        <source>within the tolerance</source>
        <translation>innerhalb der Toleranz</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="79"/>
        <source>up to 3 times the tolerance</source>
        <translation>bis zum Dreifachen der Toleranz</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="80"/>
        <source>more than 3 times the tolerance</source>
        <translation>mehr als das Dreifache der Toleranz</translation>
    </message>
    <message>
        <location filename="../ui/gcp_table.py" line="131"/>
        <source>edited since the last adjustment: run Georeference to update</source>
        <translation>seit der letzten Ausgleichung bearbeitet: 'Georeferenzieren' ausführen zum Aktualisieren</translation>
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
        <translation>Kamerapositionen (CSV)</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="98"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="99"/>
        <source>GCP residuals</source>
        <translation>Passpunkt-Residuen</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="100"/>
        <source>Camera centres (world)</source>
        <translation>Projektionszentren (Welt)</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="190"/>
        <source>outlier left out: {}</source>
        <translation>Ausreißer ausgelassen: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="145"/>
        <source>CRS {}; control RMSE XY {} m, Z {} m; check RMSE XY {} m, Z {} m</source>
        <translation>KBS {}; Passpunkte RMSE XY {} m, Z {} m; Kontrollpunkte RMSE XY {} m, Z {} m</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="178"/>
        <source>GCP layer {} lacks the field &apos;{}&apos; (needs name, image, px, py)</source>
        <translation>Dem Passpunktlayer {} fehlt das Feld '{}' (benötigt name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Georeference</source>
        <translation>Georeferenzieren</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Aligned workspace</source>
        <translation>Ausgerichteter Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Ground control file</source>
        <translation>Passpunktdatei</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Ground control layer</source>
        <translation>Passpunktlayer</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Check points</source>
        <translation>Kontrollpunkte</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Use EXIF GPS positions</source>
        <translation>EXIF-GPS-Positionen verwenden</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Target CRS</source>
        <translation>Ziel-KBS</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Refine camera calibration</source>
        <translation>Kamerakalibrierung verfeinern</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>GCP pixels measured on upright photos</source>
        <translation>GCP-Pixel auf aufrechten Fotos gemessen</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="134"/>
        <source>Give ground control (Ground control file or layer: GCPS, GCP_LAYER) and/or camera positions (Camera positions (CSV) or Use EXIF GPS positions: CAMERA_POSITIONS, USE_EXIF_GPS)</source>
        <translation>Passpunkte (Passpunktdatei oder Passpunktlayer: GCPS, GCP_LAYER) und/oder Kamerapositionen (Kamerapositionen (CSV) oder EXIF-GPS-Positionen verwenden: CAMERA_POSITIONS, USE_EXIF_GPS) angeben</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Reference orthophoto</source>
        <translation>Referenz-Orthophoto</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Reference DSM</source>
        <translation>Referenz-DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Reference resolution for web layers (m, 0: auto)</source>
        <translation>Referenzauflösung für Weblayer (m, 0: auto)</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="80"/>
        <source>Area to fetch from web layers</source>
        <translation>Aus Weblayern abzurufender Bereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="101"/>
        <source>Automatic GCPs kept</source>
        <translation>Behaltene automatische Passpunkte</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="164"/>
        <source>Automatic control needs both a reference orthophoto and a reference DSM (REFERENCE_ORTHO, REFERENCE_DSM); {} is missing</source>
        <translation>Automatische Passpunkte brauchen ein Referenz-Orthophoto und ein Referenz-DOM (REFERENCE_ORTHO, REFERENCE_DSM); {} fehlt</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="177"/>
        <source>Target CRS {} is not used: automatic control georeferences in the reference orthophoto&apos;s CRS {}</source>
        <translation>Ziel-KBS {} wird nicht verwendet: automatische Passpunkte georeferenzieren im KBS {} des Referenz-Orthophotos</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="194"/>
        <source>Automatic control: {} automatic GCPs kept; CRS {}; check RMSE XY {} m, Z {} m</source>
        <translation>Automatische Passpunkte: {} automatische Passpunkte behalten; KBS {}; Kontroll-RMSE XY {} m, Z {} m</translation>
    </message>
    <message>
        <location filename="../processing_provider/georeference.py" line="129"/>
        <source>Reference DSM {} given alone (DEM control) must be a raster file on disk; a web layer is fetched only for the automatic control, with a reference orthophoto</source>
        <translation>Allein angegebenes Referenz-DOM {} (DGM-Passpunkte) muss eine Rasterdatei auf dem Datenträger sein; ein Weblayer wird nur für die automatischen Passpunkte abgerufen, mit einem Referenz-Orthophoto</translation>
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
        <translation>Legt den ausgerichteten Block mit Passpunkten (GCPs) und/oder Kamerapositionen in einem echten Koordinatenbezugssystem fest. Sie wirken in der Bündelblockausgleichung, so dass sie auch Drift und Verbiegung des Blocks beseitigen, was eine 7-Parameter-Transformation (Helmert) nicht kann. Kontrollpunkte nehmen an der Ausgleichung nicht teil: sie werden danach trianguliert und mit ihren vermessenen Koordinaten verglichen.

Passpunktdatei: eine OpenDroneMap gcp_list.txt (KBS-Zeile, dann 'x y z px py image [name]') oder eine CSV-Punktdatei mit passender '&lt;name&gt;_observations.csv'. Passpunktlayer: alternativ ein Punktlayer mit einem Objekt je Messung und den Feldern name, image, px, py (optional z, sx, sy, sz, role).
Kontrollpunkte: durch Kommas getrennte Namen, die zu Kontrollpunkten werden.
Kamerapositionen: CSV 'image,x,y,z[,sigma]' (optionale KBS-Zeile). EXIF-GPS-Positionen verwenden: das GPS der Fotos verwenden.
Ziel-KBS: Vorgabe ist das KBS der Passpunktdatei. Kamerakalibrierung verfeinern: die Ausgleichung verfeinert Brennweite, Bildhauptpunkt und Verzeichnung.
GCP-Pixel auf aufrechten Fotos gemessen: ankreuzen, wenn die Pixelkoordinaten auf den Fotos gemessen wurden, wie sie nach ihrer EXIF-Orientierung aufrecht gezeigt werden (wie in Webbrowsern und Bildbetrachtern); sie werden in das gespeicherte Pixelraster jedes Fotos umgerechnet (ungedreht gespeicherte Fotos bleiben unverändert).
Ausreißer (eine falsche Messung, ein Tippfehler in einer Koordinate) werden erkannt, im Protokoll genannt und ausgelassen.

Mit einem Referenz-Orthophoto und einem Referenz-DOM (ein beliebiger Rasterlayer: eine Datei oder ein WMS-, XYZ- oder WCS-Layer, der für die Ausdehnung des Blocks nach georef/reference-ortho.tif und georef/reference-dsm.tif gespeichert wird) wird der Block ohne von Hand gesetzte Passpunkte georeferenziert, wie es 'Automatische Passpunkte aus einem Referenz-Orthophoto' tut; das Ergebnis ist im KBS des Referenz-Orthophotos (ein Web-Mercator- oder geographischer Layer wird im KBS des DOM gespeichert, sonst in der UTM-Zone). Zusätzlich angegebene Passpunkte legen den Block nicht fest: alle ihre Punkte werden Kontrollpunkte, ein unabhängiges Maß der automatischen Passpunkte. Kamerapositionen oder EXIF-GPS-Positionen verwenden geben die ungefähre Lage (sonst EXIF-GPS, wenn drei Fotos es tragen, sonst werden Drehung und Maßstab gesucht). Die Kalibrierung wird in jedem Fall verfeinert (Brennweite und Verzeichnung: die automatischen Passpunkte bestimmen sie).
Ein allein angegebenes Referenz-DOM (eine DGM-Datei in einem beliebigen projizierten KBS, Höhen in Metern oder Fuß) fügt DGM-Passpunkte hinzu: nach der Ausgleichung werden die Punkte des dünnen Modells des Blocks darauf koregistriert (Verschiebung, Kippung, Wölbung), und der Block wird mit aus dem DGM abgeleiteten Passpunkten (dem001, ...) erneut ausgeglichen, die Kippung, Höhenversatz und Wölbung beseitigen, die die Fotos nicht sehen können; die Koregistrierung wird protokolliert und in georef/dem_control.json gespeichert. Höhen: die der Passpunkte, wenn es welche gibt, sonst die des DGM (die Höhen der Kamerapositionen werden darauf verschoben). Ohne Passpunkte oder Kamerapositionen platziert das EXIF-GPS der Fotos den Block. Ein DGM, das neben dem Block liegt oder für ihn zu grob ist, wird vor der Ausgleichung abgelehnt.
Referenzauflösung: Meter je Pixel, mit denen ein Weblayer gespeichert wird (0: 0,25 m; das DOM mit der doppelten, mindestens 0,5 m). Abzurufender Bereich: die Ausdehnung, für die ein Weblayer gespeichert wird; leer: die EXIF-GPS-Positionen der Fotos mit einem Rand, sonst die Ausdehnung der anderen Referenz.
Ausgaben: neben den üblichen die Zahl der automatischen Passpunkte, die die Ausgleichung behalten hat (keine ohne automatische Passpunkte).</translation>
    </message>
</context>
<context>
    <name>OrthorectifyImageAlgorithm</name>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="73"/>
        <source>Image</source>
        <translation>Bild</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>DSM</source>
        <translation>DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Mode</source>
        <translation>Modus</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="94"/>
        <source>Orthophoto</source>
        <translation>Orthophoto</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="95"/>
        <source>GCP residuals</source>
        <translation>Passpunkt-Residuen</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="97"/>
        <source>GCP residual RMSE (pixels)</source>
        <translation>RMSE der Passpunktresiduen (Pixel)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="99"/>
        <source>Planar rectification: 95th percentile of its offset from the true position (CRS units)</source>
        <translation>Ebene Entzerrung: 95. Perzentil ihres Versatzes gegen die wahre Lage (KBS-Einheiten)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="128"/>
        <source>RESIDUALS must be a GeoPackage (.gpkg) file, got {}</source>
        <translation>RESIDUALS muss eine GeoPackage-Datei (.gpkg) sein, erhalten: {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="143"/>
        <source>{} ({}): {:.2f} px</source>
        <translation>{} ({}): {:.2f} px</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="110"/>
        <source>GCP layer {} lacks the field &apos;{}&apos; (needs name, image, px, py)</source>
        <translation>Dem Passpunktlayer {} fehlt das Feld '{}' (benötigt name, image, px, py)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Orthorectify image</source>
        <translation>Bild orthorektifizieren</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Ground control file</source>
        <translation>Passpunktdatei</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Ground control point layer</source>
        <translation>Passpunktlayer</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Known orientation</source>
        <translation>Bekannte Orientierung</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Focal length (mm)</source>
        <translation>Brennweite (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Sensor width (mm)</source>
        <translation>Sensorbreite (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Resolution (0 = automatic)</source>
        <translation>Auflösung (0 = automatisch)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Output CRS</source>
        <translation>Ausgabe-KBS</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>True orthophoto on the DSM</source>
        <translation>Echtes Orthofoto auf dem DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Planar rectification (flat ground)</source>
        <translation>Ebene Entzerrung (flaches Gelände)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Search radius (m)</source>
        <translation>Suchradius (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="98"/>
        <source>Automatic GCPs used</source>
        <translation>Verwendete automatische Passpunkte</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="117"/>
        <source>Give ground control points observed in the image (Ground control file or Ground control point layer: GCPS, GCP_LAYER), its Known orientation (ORIENTATION) or a Reference orthophoto for automatic control (REFERENCE_ORTHO)</source>
        <translation>Im Bild gemessene Passpunkte angeben (Passpunktdatei oder Passpunktlayer: GCPS, GCP_LAYER), seine bekannte Orientierung (ORIENTATION) oder ein Referenz-Orthophoto für automatische Passpunkte (REFERENCE_ORTHO)</translation>
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
        <translation>Orthorektifiziert ein Foto — auch eines, das zu keinem Block gehört, etwa eine einzelne Schrägaufnahme oder ein alter Abzug — auf einem vorhandenen DOM, zum Beispiel einem DOM aus Airborne Laserscanning (ALS) in beliebigem KBS (es wird im Lauf umprojiziert).

Position und Lage der Kamera ergeben sich aus im Foto gemessenen Passpunkten (räumlicher Rückwärtsschnitt: mindestens 4 Punkte; ein falscher Punkt unter 5 oder mehr wird gefunden und ausgelassen; ab 6 Punkten werden auch Brennweite und radiale Verzeichnung k1 geschätzt, wo die Punkte sie bestimmen) oder aus einer bekannten Orientierung.

Bild: das Foto. DSM: Höhenraster (für ein wahres Orthophoto nötig).
Passpunktdatei: eine OpenDroneMap gcp_list.txt oder CSV-Punktdatei mit Messungen in diesem Bild; oder Passpunktlayer: ein Punktlayer mit einem Objekt je Messung und den Feldern name, image, px, py (optional z, role; Pixelursprung in der linken oberen Ecke, y nach unten).
Bekannte Orientierung: statt Passpunkten eine Datei mit x y z omega phi kappa (Grad, photogrammetrische Konvention; eine Kopfzeile wie von Pix4D geschrieben, oder JSON), optional focal_mm, sensor_width_mm, cx, cy, k1, k2, p1, p2 und eine KBS-Zeile.
Referenz-Orthophoto (automatische Passpunkte): ohne Passpunkte und ohne bekannte Orientierung wird das Foto diesem Orthophoto zugeordnet (beliebiges KBS, beliebige Auflösung; das DOM ist dann das Referenz-DOM), und die Zuordnungen werden automatische Passpunkte (auto_001, ...) für den räumlichen Rückwärtsschnitt: kein von Hand gesetzter Punkt, die Blickrichtung muss nicht bekannt sein, auch Schrägaufnahmen gehen, und die Brennweite wird geschätzt, wenn das Foto keine hat. Ungefährer Ort: ein Punkt am Boden, den das Foto zeigt (beliebiges KBS; leer = irgendwo auf der Referenz); Suchradius: wie weit er danebenliegen darf (Meter). Das Protokoll nennt, wie viele Zuordnungen jeden Schritt überstanden haben; die Passpunkt-Residuen führen die automatischen Passpunkte auf.
Brennweite und Sensorbreite: innere Orientierung in mm (die lange Seite des Sensors); 0 oder leer = die EXIF-Brennweite.
Modus: ein wahres Orthophoto auf dem DOM oder eine ebene (projektive) Entzerrung über die Passpunkte zum Vergleich auf flachem Gelände; mit DOM sagen das Protokoll und die Ausgabe 'Ebene Entzerrung: 95. Perzentil ihres Versatzes', wie weit das ebene Ergebnis wegen des Reliefs abweicht.
Auflösung: Zellgröße in KBS-Einheiten (0 = die Bodenauflösung).
Ausgabe-KBS: Vorgabe ist das KBS der Passpunkte oder der bekannten Orientierung.
Passpunkt-Residuen: GeoPackage der Passpunkte mit ihren Residuen in Pixeln (und Metern in der Ebene).</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Reference orthophoto</source>
        <translation>Referenz-Orthophoto</translation>
    </message>
    <message>
        <location filename="../processing_provider/orthorectify_image.py" line="75"/>
        <source>Rough location</source>
        <translation>Ungefährer Ort</translation>
    </message>
</context>
<context>
    <name>PhotoPanel</name>
    <message>
        <location filename="../ui/photo_viewer.py" line="472"/>
        <source>Only photos that probably see the point</source>
        <translation>Nur Fotos, die den Punkt voraussichtlich zeigen</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="475"/>
        <source>Fit</source>
        <translation>Einpassen</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="475"/>
        <source>Show the whole photo (F)</source>
        <translation>Das ganze Foto zeigen (F)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="476"/>
        <source>Zoom to point</source>
        <translation>Auf Punkt zoomen</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="476"/>
        <source>Zoom to the observation or prediction (Z)</source>
        <translation>Auf die Messung oder Vorhersage zoomen (Z)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="478"/>
        <source>Confirm</source>
        <translation>Übernehmen</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="478"/>
        <source>Accept the predicted position (Space)</source>
        <translation>Die vorhergesagte Position übernehmen (Leertaste)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="480"/>
        <source>Confirm &amp;&amp; next</source>
        <translation>Übernehmen &amp;&amp; weiter</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="480"/>
        <source>Accept the prediction and show the next photo to place (Enter)</source>
        <translation>Die Vorhersage übernehmen und das nächste zu messende Foto zeigen (Eingabetaste)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="483"/>
        <source>Remove</source>
        <translation>Entfernen</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="483"/>
        <source>Remove the observation in this photo (Delete)</source>
        <translation>Die Messung in diesem Foto entfernen (Entf)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="683"/>
        <source>{} (predicted)</source>
        <translation>{} (vorhergesagt)</translation>
    </message>
    <message>
        <location filename="../ui/photo_viewer.py" line="589"/>
        <source>Shown upright (EXIF orientation {}: stored {} x {} px); pixel coordinates are those of the stored grid, as COLMAP and gcp_list.txt use them</source>
        <translation>Aufrecht gezeigt (EXIF-Ausrichtung {}: gespeichert {} x {} px); die Pixelkoordinaten sind die des gespeicherten Rasters, wie COLMAP und gcp_list.txt sie verwenden</translation>
    </message>
</context>
<context>
    <name>PrepareImagesAlgorithm</name>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Folder of images</source>
        <translation>Bilderordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Workspace folder</source>
        <translation>Arbeitsbereich-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Flag images below this fraction of the set&apos;s median blur score</source>
        <translation>Bilder unter diesem Bruchteil des mittleren Schärfewerts des Satzes markieren</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Fiducial mark type</source>
        <translation>Art der Rahmenmarken</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Fiducial positions</source>
        <translation>Lage der Rahmenmarken</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Template image of one fiducial mark</source>
        <translation>Vorlagenbild einer Rahmenmarke</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Scan resolution in dpi when not in the files (0 = from the files)</source>
        <translation>Scanauflösung in dpi, wenn nicht in den Dateien (0 = aus den Dateien)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="116"/>
        <source>Folder of prepared images</source>
        <translation>Ordner der vorbereiteten Bilder</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="117"/>
        <source>Flagged images</source>
        <translation>Markierte Bilder</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="118"/>
        <source>Excluded images</source>
        <translation>Ausgeschlossene Bilder</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="119"/>
        <source>Screening record (JSON)</source>
        <translation>Prüfprotokoll (JSON)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="156"/>
        <source>{} images: {} flagged, {} excluded, {} in the prepared folder</source>
        <translation>{} Bilder: {} markiert, {} ausgeschlossen, {} im vorbereiteten Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="158"/>
        <source>Blurriest first (blur score, % of the set&apos;s median):</source>
        <translation>Unschärfste zuerst (Schärfewert, % des Medians des Satzes):</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="166"/>
        <source>Prepared scans: {} x {} px, pixel size {:.6g} {}{}</source>
        <translation>Vorbereitete Scans: {} x {} px, Pixelgröße {:.6g} {}{}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Prepare images</source>
        <translation>Bilder vorbereiten</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="151"/>
        <source>MASKS layer &apos;{}&apos;</source>
        <translation>MASKS-Layer '{}'</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="186"/>
        <source>feature {}</source>
        <translation>Objekt {}</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="190"/>
        <source>MASKS layer &apos;{}&apos;: {} has no geometry: skipped</source>
        <translation>MASKS-Layer '{}': {} hat keine Geometrie: übersprungen</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="193"/>
        <source>MASKS layer &apos;{}&apos;: {} is a {} geometry, not a polygon</source>
        <translation>MASKS-Layer '{}': {} ist eine {}-Geometrie, kein Polygon</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Smallest blur score (0 = relative only)</source>
        <translation>Kleinster Schärfewert (0 = nur relativ)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="85"/>
        <source>Leave flagged images out</source>
        <translation>Markierte Bilder weglassen</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="92"/>
        <source>Mask polygons</source>
        <translation>Maskenpolygone</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="95"/>
        <source>Sky masks for oblique photos</source>
        <translation>Himmelsmasken für Schrägaufnahmen</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="96"/>
        <source>Scanned film (fiducial marks)</source>
        <translation>Gescannter Film (Rahmenmarken)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="97"/>
        <source>Fiducial coordinates (mm)</source>
        <translation>Rahmenmarken-Koordinaten (mm)</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="113"/>
        <source>Prepared images</source>
        <translation>Vorbereitete Bilder</translation>
    </message>
    <message>
        <location filename="../processing_provider/prepare_images.py" line="100"/>
        <source>Calibrated focal length (mm)</source>
        <translation>Kalibrierte Brennweite (mm)</translation>
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
        <translation>Prüft einen Ordner mit Fotos auf Unschärfe und Belichtung und findet bei gescanntem historischem Film die Rahmenmarken und rechnet jeden Scan in einen gemeinsamen Kamerarahmen um. Das Ergebnis ist ein Ordner vorbereiteter Bilder für 'Bilder ausrichten' und der Arbeitsbereich-Ordner, der je Bild eine Entscheidung festhält (screening.json) für den Genauigkeitsbericht.

Der Schärfewert ist die Varianz des Laplace-Operators auf einer grauen Kopie von 1024 px Breite, 90. Perzentil eines Rasters von 8 x 6 Kacheln (Himmel oder Wasser in einem Teil des Bildes zählt nicht dagegen). Höher ist schärfer. Ein Bild wird als 'unscharf' markiert unter einem Bruchteil des Medians des Satzes (Bilder unter diesem Bruchteil des mittleren Schärfewerts des Satzes markieren, erweitert) oder unter dem Kleinsten Schärfewert, wenn gesetzt (0 = nur relativ zum Satz; absolute Werte hängen von der Szene ab: Sand erreicht weit weniger als Dächer).
Bilder mit mehr als 5 % beschnittenen Lichtern oder Schatten, einer mittleren Helligkeit weit weg von der des Satzes oder einem sehr kleinen Dynamikumfang werden wegen ihrer Belichtung markiert. Mit 'Markierte Bilder weglassen' werden sie aus dem vorbereiteten Ordner weggelassen; sonst bleiben sie und werden nur gemeldet.

Maskenpolygone: optionaler Polygon-Layer mit Bereichen, die Ausrichtung und Orthophoto ignorieren sollen (ein Ausleger, der Schatten der Drohne, ein Datumsstempel, ein Bildrand) in den Pixelkoordinaten des Bildes: Ursprung in der oberen linken Ecke, x nach rechts, y nach unten, oder y = -Zeile, wie der QGIS-Georeferenzierer ein Foto zeigt (erkannt, wenn jedes y &lt;= 0 ist). Ein Textfeld 'image' nennt das Bild, zu dem ein Polygon gehört; leer (oder ohne dieses Feld) gilt es für jedes Bild. Die Polygone werden in die Masken je Bild geschrieben (workspace/masks/&lt;Bild&gt;.png, mit einer vorhandenen Maske vereinigt): 'Bilder ausrichten' findet darunter keine Merkmale, das Orthophoto verwendet diese Pixel nicht, und Schärfe und Belichtung werden außerhalb gemessen. Bei gescanntem Film sind es die Koordinaten der vorbereiteten Bilder (der gemeinsame Rahmenmarken-Rahmen, so passt ein Polygon zu jedem Bild).
Himmelsmasken für Schrägaufnahmen: der Himmel (samt Wolken) und der Dunst am Horizont werden automatisch gefunden und in die Masken je Bild geschrieben, damit 'Bilder ausrichten' keine Verknüpfungspunkte aus Wolken nimmt, die zwischen den Aufnahmen ziehen; ein Foto ohne Himmel (senkrecht nach unten) erhält keine Himmelsmaske.

Gescannter Film (Rahmenmarken): Rahmenmarken (Kreuze, Punkte, Punkte in Kreisen; in den Ecken und/oder Seitenmitten, oder wie ein Vorlagenbild einer Marke) werden auf Bruchteile eines Pixels gefunden, jeder Scan wird durch eine affine Transformation in den gemeinsamen Rahmenmarken-Rahmen umgerechnet, alle gleich groß und mit dem Bildhauptpunkt in der Mitte, und Masken (workspace/masks) verbergen Filmrand, Datenstreifen und die Marken vor der Zuordnung. Rahmenmarken-Koordinaten: die kalibrierten Rahmenmarken-Koordinaten des Kalibrierzertifikats in mm, als Dateipfad oder eingefügter Text, eine Zeile 'id x y' je Marke (x nach rechts, y nach oben), optional 'PP x y' (Bildhauptpunkt) und 'focal f'. Ohne sie wird die mittlere Anordnung des Satzes verwendet, zentriert auf die Rahmenmitte. Mit der Kalibrierten Brennweite (0 = unbekannt; oder 'focal' im Zertifikat) tragen die vorbereiteten Bilder die Brennweite in Pixeln für die Ausrichtung.

Vorbereitete Bilder: der Ordner der vorbereiteten Bilder (wird als Ganzes ersetzt; er muss neu, leer oder von einem früheren Lauf geschrieben sein); wenn ausgelassen, &lt;workspace&gt;/prepared.</translation>
    </message>
</context>
<context>
    <name>ReliefVisualisationAlgorithm</name>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="43"/>
        <source>Workspace folder</source>
        <translation>Arbeitsbereich-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>Surface</source>
        <translation>Oberfläche</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>DTM</source>
        <translation>DGM</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>DSM</source>
        <translation>DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>Visualisation</source>
        <translation>Visualisierung</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="55"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="76"/>
        <source>Give a workspace folder, or an elevation raster and where to write the visualisation</source>
        <translation>Geben Sie einen Arbeitsbereich-Ordner an, oder ein Höhenraster und wohin die Visualisierung geschrieben wird</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisation</source>
        <translation>Reliefvisualisierung</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="41"/>
        <source>VAT blend</source>
        <translation>VAT-Mischung</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="45"/>
        <source>Elevation raster</source>
        <translation>Höhenraster</translation>
    </message>
    <message>
        <location filename="../processing_provider/relief_visualisation.py" line="52"/>
        <source>Relief raster</source>
        <translation>Reliefraster</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisations for reading earthworks, hollow ways, ridge and furrow and field boundaries, computed with rvt-py (the Relief Visualization Toolbox&apos;s library) with RVT&apos;s default parameters, converted from the 1 m DEMs RVT was made for to this raster&apos;s cell size.

Workspace folder: a workspace with a DTM (Build DTM) or DSM.
Elevation raster: any DTM/DSM in a projected CRS instead (optional).
Surface: the workspace&apos;s DTM (bare earth, default) or DSM.
Visualisation: sky-view factor, openness (positive, negative), simple local relief model, multi-scale relief model, multi-direction hillshade, local dominance, or the VAT blend (visualisation for archaeological topography).
Relief raster: where to write it (default: &lt;workspace&gt;/terrain/relief/&lt;surface&gt;-&lt;visualisation&gt;.tif).</source>
        <translation>Reliefvisualisierungen zum Lesen von Erdwerken, Hohlwegen, Wölbäckern und Flurgrenzen, berechnet mit rvt-py (der Bibliothek der Relief Visualization Toolbox) mit den Standardparametern von RVT, umgerechnet von den 1-m-Geländemodellen, für die RVT gemacht ist, auf die Zellgröße dieses Rasters.

Arbeitsbereich-Ordner: ein Arbeitsbereich mit DGM (DGM erzeugen) oder DOM.
Höhenraster: stattdessen ein beliebiges DGM/DOM in einem projizierten KBS (optional).
Oberfläche: das DGM des Arbeitsbereichs (nackte Erde, Vorgabe) oder sein DOM.
Visualisierung: Sky-View-Faktor, Offenheit (positiv, negativ), einfaches lokales Reliefmodell, mehrskaliges Reliefmodell, Schummerung aus mehreren Richtungen, lokale Dominanz oder die VAT-Mischung (Visualisierung für archäologische Topographie).
Reliefraster: wohin es geschrieben wird (Vorgabe: &lt;workspace&gt;/terrain/relief/&lt;surface&gt;-&lt;visualisation&gt;.tif).</translation>
    </message>
</context>
<context>
    <name>Report</name>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>height (m)</source>
        <translation>Höhe (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Summary</source>
        <translation>Übersicht</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Orientation quality</source>
        <translation>Qualität der Orientierung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Georeferencing</source>
        <translation>Georeferenzierung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Uncertainty</source>
        <translation>Unsicherheit</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Products</source>
        <translation>Produkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>images aligned</source>
        <translation>Bilder ausgerichtet</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean reprojection error</source>
        <translation>mittlerer Rückprojektionsfehler</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ground sample distance</source>
        <translation>Bodenauflösung (GSD)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>area</source>
        <translation>Fläche</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>check RMSE XY</source>
        <translation>Kontroll-RMSE XY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>check RMSE Z</source>
        <translation>Kontroll-RMSE Z</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>NSSDA horizontal 95 %</source>
        <translation>NSSDA horizontal 95 %</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>NSSDA vertical 95 %</source>
        <translation>NSSDA vertikal 95 %</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ASPRS 2014 horizontal class</source>
        <translation>ASPRS-2014-Lageklasse</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera position RMSE XY (the block&apos;s fit to the positions)</source>
        <translation>RMSE XY der Kamerapositionen (Passung des Blocks an die Positionen)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>tie point σXY / σZ (median; predicted ground uncertainty, datum included)</source>
        <translation>σXY / σZ der Verknüpfungspunkte (Median; vorhergesagte Unsicherheit am Boden, Datum eingeschlossen)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM valid fraction</source>
        <translation>gültiger Anteil des DOM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ArchaeoOrtho report — {}</source>
        <translation>ArchaeoOrtho-Bericht — {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>no aligned model: run &apos;Align images&apos;</source>
        <translation>kein ausgerichtetes Modell: 'Bilder ausrichten' ausführen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>no DSM / orthomosaic yet</source>
        <translation>noch kein DOM / Orthomosaik</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>{} of {} images aligned, mean reprojection error {} px</source>
        <translation>{} von {} Bildern ausgerichtet, mittlerer Rückprojektionsfehler {} px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>generated</source>
        <translation>erstellt</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>At a glance</source>
        <translation>Auf einen Blick</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Skipped:</source>
        <translation>Übersprungen:</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>automatic control points</source>
        <translation>automatische Passpunkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Where the automatic GCPs lie (triangles, coloured by their horizontal residual after the adjustment), the ones the adjustment rejected (red) and the candidates dropped before it (grey): a change between the epochs, a height the DSM does not give, a point found in one photo only.</source>
        <translation>Wo die automatischen Passpunkte liegen (Dreiecke, gefärbt nach ihrem Lageresiduum nach der Ausgleichung), die von der Ausgleichung verworfenen (rot) und die vorher ausgeschiedenen Kandidaten (grau): eine Änderung zwischen den Zeitpunkten, eine Höhe, die das DOM nicht liefert, ein Punkt, der nur in einem Foto gefunden wurde.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>step</source>
        <translation>Schritt</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>matches / points</source>
        <translation>Zuordnungen / Punkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dropped because</source>
        <translation>ausgeschieden wegen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>candidates</source>
        <translation>Kandidaten</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dropped candidates</source>
        <translation>ausgeschiedene Kandidaten</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>automatic GCPs (colour: XY residual)</source>
        <translation>automatische Passpunkte (Farbe: Residuum XY)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>XY residual (m)</source>
        <translation>Residuum XY (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Automatic control</source>
        <translation>Automatische Passpunkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>rejected by the adjustment</source>
        <translation>von der Ausgleichung verworfen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>set</source>
        <translation>Satz</translation>
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
        <translation>mittleres dX</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean dY</source>
        <translation>mittleres dY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean dZ</source>
        <translation>mittleres dZ</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>name</source>
        <translation>Name</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>role</source>
        <translation>Rolle</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>status</source>
        <translation>Status</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dXY</source>
        <translation>dXY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>obs</source>
        <translation>Beob.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean px</source>
        <translation>mittl. px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>max px</source>
        <translation>max. px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image residuals (px)</source>
        <translation>Bildresiduen (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>residual vectors</source>
        <translation>Residuenvektoren</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>group</source>
        <translation>Gruppe</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ XY</source>
        <translation>σ XY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>rigid fit σ XY</source>
        <translation>σ XY der starren Passung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>rigid fit σ Z</source>
        <translation>σ Z der starren Passung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>floor XY</source>
        <translation>Untergrenze XY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>floor Z</source>
        <translation>Untergrenze Z</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>placeholders</source>
        <translation>Platzhalter</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>estimated from</source>
        <translation>geschätzt aus</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image σ (px)</source>
        <translation>Bild-σ (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>left out as suspect</source>
        <translation>als verdächtig ausgelassen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE XY (radial)</source>
        <translation>RMSE XY (radial)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE 3D</source>
        <translation>RMSE 3D</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>max dXY</source>
        <translation>max. dXY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>max |dZ|</source>
        <translation>max. |dZ|</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera centres</source>
        <translation>Kamerazentren</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image</source>
        <translation>Bild</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>used</source>
        <translation>verwendet</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>tie-point footprint</source>
        <translation>Grundriss der Verknüpfungspunkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dZ (m)</source>
        <translation>dZ (m)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Residual vectors over the footprint</source>
        <translation>Residuenvektoren über dem Grundriss</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Outliers and suspect points</source>
        <translation>Ausreißer und verdächtige Punkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Accuracy of the control given without sigmas, estimated from the data</source>
        <translation>Genauigkeit der ohne Sigmas angegebenen Passpunkte, aus den Daten geschätzt</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>RMSE per set</source>
        <translation>RMSE je Satz</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Outliers, suspect points and warnings</source>
        <translation>Ausreißer, verdächtige Punkte und Warnungen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Control and check points</source>
        <translation>Pass- und Kontrollpunkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Camera-position residuals</source>
        <translation>Residuen der Kamerapositionen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>reprojection error (px)</source>
        <translation>Rückprojektionsfehler (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>observations</source>
        <translation>Beobachtungen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>track length (images per tie point)</source>
        <translation>Spurlänge (Bilder je Verknüpfungspunkt)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>tie points</source>
        <translation>Verknüpfungspunkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>reprojection error and track length histograms</source>
        <translation>Histogramme von Rückprojektionsfehler und Spurlänge</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Left: reprojection error of every tie-point observation (clipped at the 99.5th percentile). Right: number of images per tie point.</source>
        <translation>Links: Rückprojektionsfehler jeder Beobachtung eines Verknüpfungspunkts (beim 99,5. Perzentil abgeschnitten). Rechts: Anzahl der Bilder je Verknüpfungspunkt.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean error (px)</source>
        <translation>mittlerer Fehler (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>reprojection error per image</source>
        <translation>Rückprojektionsfehler je Bild</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Mean reprojection error (red: more than twice the median) and tie-point observations per image.</source>
        <translation>Mittlerer Rückprojektionsfehler (rot: mehr als das Doppelte des Medians) und Beobachtungen von Verknüpfungspunkten je Bild.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera</source>
        <translation>Kamera</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mode</source>
        <translation>Modus</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>parameter</source>
        <translation>Parameter</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>given</source>
        <translation>gegeben</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>final</source>
        <translation>endgültig</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>moved</source>
        <translation>verschoben</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>moved (σ)</source>
        <translation>verschoben (σ)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image × image</source>
        <translation>Bild × Bild</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera positions</source>
        <translation>Kamerapositionen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>shared tie points</source>
        <translation>gemeinsame Verknüpfungspunkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>image connectivity</source>
        <translation>Bildverknüpfung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean reprojection error (px)</source>
        <translation>mittlerer Rückprojektionsfehler (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dZ (m): adjusted − given</source>
        <translation>dZ (m): ausgeglichen − gegeben</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Camera positions</source>
        <translation>Kamerapositionen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Image connectivity</source>
        <translation>Bildverknüpfung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Interior orientation</source>
        <translation>Innere Orientierung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM preview with hillshade (sun from the north-west, 45°).</source>
        <translation>DOM-Vorschau mit Schummerung (Sonne aus Nordwest, 45°).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>{} preview.</source>
        <translation>{}-Vorschau.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM</source>
        <translation>DOM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Orthomosaic</source>
        <translation>Orthomosaik</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>NSSDA accuracy at 95 % confidence (FGDC-STD-007.3-1998)</source>
        <translation>NSSDA-Genauigkeit bei 95 % Konfidenz (FGDC-STD-007.3-1998)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ASPRS positional accuracy class</source>
        <translation>ASPRS-Lagegenauigkeitsklasse</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur scores</source>
        <translation>Schärfewerte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Blur score per image (orange: flagged, red: excluded).</source>
        <translation>Schärfewert je Bild (orange: markiert, rot: ausgeschlossen).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur score (higher = sharper)</source>
        <translation>Schärfewert (höher = schärfer)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>images, blurriest first</source>
        <translation>Bilder, unschärfstes zuerst</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur score</source>
        <translation>Schärfewert</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>blur / median</source>
        <translation>Schärfe / Median</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>exposure</source>
        <translation>Belichtung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>dynamic range</source>
        <translation>Dynamikumfang</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>flags</source>
        <translation>Markierungen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>decision</source>
        <translation>Entscheidung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>model</source>
        <translation>Modell</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>size (px)</source>
        <translation>Größe (px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>images</source>
        <translation>Bilder</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>parameters (pixels; distortion unitless)</source>
        <translation>Parameter (Pixel; Verzeichnung ohne Einheit)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>stage</source>
        <translation>Verarbeitungsschritt</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>parameters</source>
        <translation>Parameter</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>why</source>
        <translation>warum</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Image screening</source>
        <translation>Bildprüfung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>median</source>
        <translation>Median</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>time</source>
        <translation>Zeit</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>steps</source>
        <translation>Teilschritte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>finished</source>
        <translation>beendet</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>{} images screened: {} flagged, {} excluded, {} kept (blurriest first).</source>
        <translation>{} Bilder geprüft: {} markiert, {} ausgeschlossen, {} behalten (unschärfstes zuerst).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Cameras and calibrated parameters</source>
        <translation>Kameras und kalibrierte Parameter</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images not aligned</source>
        <translation>Nicht ausgerichtete Bilder</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Processing stages</source>
        <translation>Verarbeitungsschritte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DTM preview</source>
        <translation>DGM-Vorschau</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DTM (bare earth) preview with hillshade.</source>
        <translation>DGM (Gelände) als Vorschau mit Schummerung.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisations</source>
        <translation>Reliefdarstellungen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Relief visualisations (rvt-py, RVT&apos;s default parameters scaled to the cell size), in RVT&apos;s display ranges.</source>
        <translation>Reliefdarstellungen (rvt-py, die Standardparameter von RVT auf die Zellgröße skaliert), in den Anzeigebereichen von RVT.</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Terrain (DTM)</source>
        <translation>Gelände (DGM)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>point standard deviations</source>
        <translation>Standardabweichungen der Punkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Left: distribution of the tie points' standard deviations. Right: σZ over the block, colours clipped at the 95th percentile (precision degrades where few images overlap and away from control).</source>
        <translation>Links: Verteilung der Standardabweichungen der Verknüpfungspunkte. Rechts: σZ über dem Block, Farben beim 95. Perzentil abgeschnitten (die Präzision sinkt, wo sich wenige Bilder überlappen, und fern von Passpunkten).</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σXY</source>
        <translation>σXY</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>cameras</source>
        <translation>Kameras</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ rot x (°)</source>
        <translation>σ Rot. x (°)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ rot y (°)</source>
        <translation>σ Rot. y (°)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>σ rot z (°)</source>
        <translation>σ Rot. z (°)</translation>
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
        <translation>Passpunkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reference orthophoto</source>
        <translation>Referenz-Orthophoto</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reference DSM</source>
        <translation>Referenz-DOM</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Rough position (prior)</source>
        <translation>Grobe Position (Vorinformation)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reference CRS</source>
        <translation>KBS der Referenz</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Common resolution of the match</source>
        <translation>Gemeinsame Auflösung der Zuordnung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>CRS</source>
        <translation>KBS</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Source of the datum</source>
        <translation>Quelle des Datums</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Local frame offset (world = local + offset)</source>
        <translation>Versatz des lokalen Rahmens (Welt = lokal + Versatz)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie-point reprojection error after the adjustment</source>
        <translation>Rückprojektionsfehler der Verknüpfungspunkte nach der Ausgleichung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>GCP observation reprojection error in the adjustment (mean; control held at its coordinates within its sigmas)</source>
        <translation>Rückprojektionsfehler der Passpunktbeobachtungen in der Ausgleichung (Mittel; Passpunkte innerhalb ihrer Sigmas an ihren Koordinaten gehalten)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Mean reprojection error (mean over tie points of their mean error, as COLMAP reports it)</source>
        <translation>Mittlerer Rückprojektionsfehler (Mittel über die Verknüpfungspunkte ihres mittleren Fehlers, wie COLMAP ihn angibt)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Reprojection error of the observations: mean / median / RMS</source>
        <translation>Rückprojektionsfehler der Beobachtungen: Mittel / Median / RMS</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Largest reprojection error</source>
        <translation>Größter Rückprojektionsfehler</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Track length: mean / median / max</source>
        <translation>Spurlänge: Mittel / Median / Maximum</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Model</source>
        <translation>Modell</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>File</source>
        <translation>Datei</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Size</source>
        <translation>Größe</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Resolution</source>
        <translation>Auflösung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Brightness step across the seamlines (median; before → after the radiometric correction)</source>
        <translation>Helligkeitssprung über die Nahtlinien (Median; vor → nach der radiometrischen Korrektur)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Valid fraction (cells with data)</source>
        <translation>Gültiger Anteil (Zellen mit Daten)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Valid fraction inside the camera centres&apos; convex hull (as the stage reports it)</source>
        <translation>Gültiger Anteil innerhalb der konvexen Hülle der Kamerazentren (wie der Schritt ihn angibt)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Inside that hull: measured / interpolated (filled holes) / removed as blunders (dense/dsm-source.tif)</source>
        <translation>Innerhalb dieser Hülle: gemessen / interpoliert (gefüllte Löcher) / als grobe Fehler entfernt (dense/dsm-source.tif)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Height range (1st–99th percentile)</source>
        <translation>Höhenbereich (1.–99. Perzentil)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Workspace</source>
        <translation>Arbeitsbereich</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images folder</source>
        <translation>Bilderordner</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Coordinate reference system</source>
        <translation>Koordinatenbezugssystem</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images given / aligned / not aligned</source>
        <translation>Bilder gegeben / ausgerichtet / nicht ausgerichtet</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie points / image observations</source>
        <translation>Verknüpfungspunkte / Bildbeobachtungen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Images given</source>
        <translation>Gegebene Bilder</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Ground sample distance (median)</source>
        <translation>Bodenauflösung (Median)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Area covered by tie points</source>
        <translation>Von Verknüpfungspunkten bedeckte Fläche</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Ground sample distance</source>
        <translation>Bodenauflösung</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DSM cells on the ground (SMRF ground filter)</source>
        <translation>DOM-Zellen am Boden (SMRF-Bodenfilter)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>DTM cells interpolated (under objects, in holes)</source>
        <translation>Interpolierte DGM-Zellen (unter Objekten, in Löchern)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Measured / interpolated cells</source>
        <translation>Gemessene / interpolierte Zellen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Classified point cloud</source>
        <translation>Klassifizierte Punktwolke</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Contours</source>
        <translation>Höhenlinien</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Datum</source>
        <translation>Datum</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Sigma0 (a posteriori, unit weight = 1 px)</source>
        <translation>Sigma0 (a posteriori, Gewichtseinheit = 1 px)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Redundancy</source>
        <translation>Redundanz</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Observations / points</source>
        <translation>Beobachtungen / Punkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Camera position σXY / σZ (median)</source>
        <translation>Kameraposition σXY / σZ (Median)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie point σXY / σZ (median)</source>
        <translation>Verknüpfungspunkt σXY / σZ (Median)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Tie point σXY / σZ (95th percentile)</source>
        <translation>Verknüpfungspunkt σXY / σZ (95. Perzentil)</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>GeoPackage layers</source>
        <translation>GeoPackage-Layer</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Computed in</source>
        <translation>Berechnet in</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>ground point residuals ({})</source>
        <translation>Residuen der Bodenpunkte ({})</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Per camera</source>
        <translation>Je Kamera</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera centres ({}); line width ∝ shared points</source>
        <translation>Kamerazentren ({}); Linienbreite ∝ gemeinsame Punkte</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>camera positions ({})</source>
        <translation>Kamerapositionen ({})</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>mean {} px</source>
        <translation>Mittel {} px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>median {} px</source>
        <translation>Median {} px</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Per-image table</source>
        <translation>Tabelle je Bild</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Screening table</source>
        <translation>Prüftabelle</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Parameters used</source>
        <translation>Verwendete Parameter</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>standard deviation ({})</source>
        <translation>Standardabweichung ({})</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Per camera: standard deviations</source>
        <translation>Je Kamera: Standardabweichungen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Control points: adjusted standard deviations</source>
        <translation>Passpunkte: ausgeglichene Standardabweichungen</translation>
    </message>
</context>
<context>
    <name>ResultLayers</name>
    <message>
        <location filename="../qgisio/layers.py" line="327"/>
        <source>found</source>
        <translation>gefunden</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="327"/>
        <source>not found</source>
        <translation>nicht gefunden</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="851"/>
        <source>Targets found</source>
        <translation>Gefundene Zielmarken</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="290"/>
        <source>control (used)</source>
        <translation>Passpunkt (verwendet)</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="291"/>
        <source>check point</source>
        <translation>Kontrollpunkt</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="292"/>
        <source>rejected (outlier)</source>
        <translation>verworfen (Ausreißer)</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="293"/>
        <source>not triangulated</source>
        <translation>nicht trianguliert</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="845"/>
        <source>DSM</source>
        <translation>DOM</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="791"/>
        <source>DSM hillshade</source>
        <translation>DOM-Schummerung</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="846"/>
        <source>Orthomosaic</source>
        <translation>Orthomosaik</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="847"/>
        <source>Cameras</source>
        <translation>Kameras</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="803"/>
        <source>Camera footprints</source>
        <translation>Bildfußabdrücke</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="811"/>
        <source>GCP residuals (vectors x{})</source>
        <translation>Passpunkt-Residuen (Vektoren x{})</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="848"/>
        <source>Point cloud</source>
        <translation>Punktwolke</translation>
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
        <translation>DGM</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="819"/>
        <source>DTM hillshade</source>
        <translation>DGM-Schummerung</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="850"/>
        <source>Contours</source>
        <translation>Höhenlinien</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="452"/>
        <source>{} — {}</source>
        <translation>{} — {}</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="408"/>
        <source>Spectral index</source>
        <translation>Spektralindex</translation>
    </message>
    <message>
        <location filename="../qgisio/layers.py" line="844"/>
        <source>RGB orthomosaic</source>
        <translation>RGB-Orthomosaik</translation>
    </message>
    <message>
        <location filename="../qgisio/scene_layers.py" line="43"/>
        <source>3-D model</source>
        <translation>3-D-Modell</translation>
    </message>
    <message>
        <location filename="../qgisio/legend.py" line="11"/>
        <source>DTM (bare earth)</source>
        <translation>DGM (Gelände)</translation>
    </message>
    <message>
        <location filename="../qgisio/scene_layers.py" line="111"/>
        <source>3D Tiles not loaded: {}</source>
        <translation>3D Tiles nicht geladen: {}</translation>
    </message>
</context>
<context>
    <name>RunPipelineAlgorithm</name>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Folder of images</source>
        <translation>Bilderordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Workspace folder</source>
        <translation>Arbeitsbereich-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Camera positions (CSV)</source>
        <translation>Kamerapositionen (CSV)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Pair selection</source>
        <translation>Paarauswahl</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Camera model</source>
        <translation>Kameramodell</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Write the accuracy report</source>
        <translation>Genauigkeitsbericht schreiben</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="154"/>
        <source>DSM</source>
        <translation>DOM</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="155"/>
        <source>Orthomosaic</source>
        <translation>Orthomosaik</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="160"/>
        <source>Accuracy report (HTML)</source>
        <translation>Genauigkeitsbericht (HTML)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="227"/>
        <source>Seconds per stage: {}</source>
        <translation>Sekunden pro Stufe: {}</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Run pipeline</source>
        <translation>Gesamte Verarbeitung ausführen</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Ground control file</source>
        <translation>Passpunktdatei</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Ground control layer</source>
        <translation>Passpunktlayer</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Check points</source>
        <translation>Kontrollpunkte</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Use EXIF GPS positions</source>
        <translation>EXIF-GPS-Positionen verwenden</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Target CRS</source>
        <translation>Ziel-KBS</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Matching image size (px)</source>
        <translation>Bildgröße für die Zuordnung (px)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Refine camera calibration</source>
        <translation>Kamerakalibrierung verfeinern</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>DSM resolution (m)</source>
        <translation>DOM-Auflösung (m)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Matching quality</source>
        <translation>Zuordnungsqualität</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Seam blending</source>
        <translation>Überblendung der Nähte</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Parallel workers</source>
        <translation>Parallele Prozesse</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Dask scheduler</source>
        <translation>Dask-Scheduler</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Build the DTM</source>
        <translation>Das DGM erzeugen</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Contour interval (m, 0 = none)</source>
        <translation>Höhenlinienabstand (m, 0 = keine)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Relief visualisations</source>
        <translation>Reliefvisualisierungen</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="153"/>
        <source>DTM</source>
        <translation>DGM</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>GCP pixels measured on upright photos</source>
        <translation>GCP-Pixel auf aufrechten Fotos gemessen</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Sky masks (oblique photos)</source>
        <translation>Himmelsmasken (Schrägaufnahmen)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Camera calibration file</source>
        <translation>Kamerakalibrierungsdatei</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Interior orientation</source>
        <translation>Innere Orientierung</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Orthomosaic resolution (CRS units, 0 = GSD)</source>
        <translation>Orthomosaik-Auflösung (KBS-Einh., 0 = GSD)</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Targets to find</source>
        <translation>Zu findende Zielmarken</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Target kind</source>
        <translation>Art der Zielmarken</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="185"/>
        <source>Give ground control (Ground control file or layer, or targets to find: GCPS, GCP_LAYER, TARGETS) and/or camera positions (Camera positions (CSV) or Use EXIF GPS positions: CAMERA_POSITIONS, USE_EXIF_GPS): the DSM and orthophoto need a georeferenced block</source>
        <translation>Geben Sie Passpunkte (Passpunktdatei oder Passpunktlayer oder zu findende Zielmarken: GCPS, GCP_LAYER, TARGETS) und/oder Kamerapositionen (Kamerapositionen (CSV) oder EXIF-GPS-Positionen verwenden: CAMERA_POSITIONS, USE_EXIF_GPS) an: DOM und Orthophoto brauchen einen georeferenzierten Block</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Calibration panel folder</source>
        <translation>Kalibrierpanel-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Panel reflectance</source>
        <translation>Panelreflexion</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Panel window</source>
        <translation>Panelfenster</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Capture radiometry</source>
        <translation>Aufnahme-Radiometrie</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="156"/>
        <source>RGB orthomosaic (a rig&apos;s RGB frames)</source>
        <translation>RGB-Orthomosaik (die RGB-Bilder eines Rigs)</translation>
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
        <translation>Die gesamte Verarbeitung in einem Aufruf, für die Stapelverarbeitung: Bilder ausrichten, Georeferenzieren, DOM erzeugen, Orthophoto erzeugen und Genauigkeitsbericht in einem Arbeitsbereich. Es werden dieselben Funktionen wie in den einzelnen Algorithmen aufgerufen; ein erneuter Lauf setzt fort (bereits berechnete Merkmale, Zuordnungen und Stereopaare werden wiederverwendet).

Bilderordner: die Fotos; ein Ordner mit den Kanaldateien einer Multispektralkamera (Parrot Sequoia, MicaSense, DJI Multispektral) wird erkannt, und ihre Aufnahmen werden zuerst zu mehrkanaligen Fotos in &lt;workspace&gt;/captures gestapelt (wie 'Multispektrale Aufnahmen stapeln'), die die Kette dann nimmt. Arbeitsbereich-Ordner: wohin alle Produkte geschrieben werden.
Aufnahme-Radiometrie (erweitert; mit einem Kanalordner): wie Radiometrie in 'Multispektrale Aufnahmen stapeln': normalisiert (Standard) zieht von jedem Kanal seinen Dunkelwert ab, korrigiert seine Vignettierung nach dem Modell der Datei und normalisiert Belichtungszeit und Verstärkung auf die des Blocks; Einstrahlung teilt zusätzlich durch die Einstrahlung des Sonnensensors für diesen Kanal (Werte proportional zur Reflexion, wenn sich das Licht während des Flugs ändert); roh behält die Werte wie aufgenommen. Eine Kanaldatei, der fehlt, was die Wahl braucht (eine Belichtungszeit, ein Sonnensensorwert), beendet den Lauf vor der Ausrichtung und nennt die Datei. Ein Kalibrierpanel wird ebenso korrigiert.
Kalibrierpanel-Ordner und Panelreflexion (erweitert, optional; mit einem Kanalordner): wie in 'Multispektrale Aufnahmen stapeln': die Kanaldateien der Aufnahmen des Kalibrierpanels, in einem eigenen Ordner, und die Reflexion des Panels (eine Zahl, je Kanal wie Green=0.49,Red=0.50, oder eine CSV-Datei); die gestapelten Fotos und damit das Orthomosaik enthalten dann Reflexion (float32). Ein schlechtes Panel (in seiner Mitte gesättigt oder nicht gleichmäßig, eine andere Kamera, ein fehlender Kanal, eine Reflexion für einen Kanal, den das Rig nicht hat) beendet den Lauf vor der Ausrichtung und nennt die Datei; ebenso ein Panel, das mit einem Bilderordner gegeben wird, der kein Kanalordner ist. Panelfenster (erweitert): die Seite des mittleren Quadrats, in dem das Panel gemessen wird, als Anteil der kurzen Seite des Fotos.
Die Georeferenzierung braucht Passpunkte (eine Passpunktdatei oder ein Passpunktlayer, Kontrollpunkte werden zurückgehalten) und/oder Kamerapositionen (eine CSV-Datei der Kamerapositionen oder EXIF-GPS-Positionen verwenden): ohne sie wird die Verarbeitung abgelehnt, da ein DOM einen metrischen Maßstab und eine Lotrichtung braucht. GCP-Pixel auf aufrechten Fotos gemessen: wie bei 'Georeferenzieren' (die Pixelkoordinaten auf den Fotos gemessen, wie sie nach ihrer EXIF-Orientierung aufrecht gezeigt werden).
Zu findende Zielmarken (statt einer Passpunktdatei oder eines Passpunktlayers): die vermessenen Koordinaten von am Boden ausgelegten Zielmarken; nach der Ausrichtung findet 'Zielmarken finden' sie auf den Fotos, und seine Messungen sind die Passpunkte (Art der Zielmarken, erweitert: wie in 'Zielmarken finden').
Kamerakalibrierungsdatei und Innere Orientierung (erweitert): wie in 'Bilder ausrichten' (eine kalibrierte Kamera durch die ganze Kette festgehalten oder mit ihren Standardabweichungen verbessert).
Himmelsmasken (Schrägaufnahmen): zuerst findet eine Stufe 'Bilder vorbereiten' den Himmel und den Dunst am Horizont in jedem Foto und maskiert sie, damit kein Verknüpfungs- oder DOM-Punkt aus dem Himmel stammt; die vorbereiteten Fotos werden ausgerichtet (standardmäßig aus: senkrecht aufgenommene Fotos brauchen keine).
Das DGM erzeugen: nach dem DOM ein DGM der nackten Erde (wie 'DGM erzeugen'). Höhenlinienabstand (erweitert): Höhenlinien des DGM in diesem Abstand (wie 'Höhenlinien'; 0 = keine). Reliefvisualisierungen (erweitert): die gewählten werden aus dem DGM berechnet (wie 'Reliefvisualisierung'). Beide brauchen das DGM.
Die übrigen Parameter sind die der einzelnen Stufen (siehe deren Hilfe); 0 bedeutet automatisch.
Ausgaben: das DOM, das Orthomosaik und der Genauigkeitsbericht (HTML) sowie die wichtigsten Kennzahlen; mit einem Kanalordner, der auch die RGB-Bilder des Rigs enthält, zusätzlich RGB-Orthomosaik (die RGB-Bilder eines Rigs): das eigene Orthomosaik dieser Bilder, &lt;orthomosaic&gt;_rgb.tif neben dem mehrkanaligen der Aufnahmen (keines, wenn kein RGB-Bild registriert ist).</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="114"/>
        <source>Build the textured 3-D model</source>
        <translation>Das texturierte 3-D-Modell erzeugen</translation>
    </message>
    <message>
        <location filename="../processing_provider/run_pipeline.py" line="161"/>
        <source>3-D model (3D Tiles)</source>
        <translation>3-D-Modell (3D Tiles)</translation>
    </message>
</context>
<context>
    <name>SpectralIndexAlgorithm</name>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Input raster</source>
        <translation>Eingaberaster</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Index</source>
        <translation>Index</translation>
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
        <translation>Ausdruck</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>NIR band number</source>
        <translation>NIR-Kanalnummer</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Red band number</source>
        <translation>Rot-Kanalnummer</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="51"/>
        <source>Red-edge band number</source>
        <translation>Red-Edge-Kanalnummer</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="61"/>
        <source>Index raster</source>
        <translation>Indexraster</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="62"/>
        <source>Cells with a value</source>
        <translation>Zellen mit Wert</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="63"/>
        <source>Lowest value</source>
        <translation>Kleinster Wert</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="64"/>
        <source>Highest value</source>
        <translation>Größter Wert</translation>
    </message>
    <message>
        <location filename="../processing_provider/spectral_index.py" line="65"/>
        <source>Mean value</source>
        <translation>Mittelwert</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Spectral index</source>
        <translation>Spektralindex</translation>
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
        <translation>Ein Vegetationsindex eines multispektralen Orthomosaiks oder eines beliebigen mehrkanaligen Rasters (einer Satellitenszene), um Bewuchsmerkmale zu sehen: über einem verfüllten Graben wächst das Getreide grüner (ein höherer Index), über einer Mauer ist es gestresst (ein niedrigerer). NDVI ist (NIR - RED) / (NIR + RED), NDRE (NIR - REDEDGE) / (NIR + REDEDGE). Eine Zelle ist NoData, wo ein verwendeter Kanal NoData oder maskiert ist (Alphakanal, Maske) oder der Nenner null ist. Das Raster wird blockweise gelesen, ein großes braucht also wenig Speicher.

Welcher Kanal NIR, Rot oder Red Edge ist, wird aus dem Raster gelesen: aus der Beschreibung des Kanals (NIR, Red, Red edge / REG / RE, Green / GRE, Blue), einem Namen oder einer Wellenlänge in seinen Metadaten (790 nm ist NIR: Rot 600-690 nm, Red Edge 690-760 nm, NIR 760-1000 nm) oder seiner Farbinterpretation; das Protokoll sagt, welcher Kanal für jeden Namen genommen wurde und warum, und ein fehlender Name listet die Kanäle des Rasters auf.

Eingaberaster: das mehrkanalige Raster.
Index: NDVI, NDRE oder der Ausdruck unten.
Ausdruck: eine Formel der Kanäle, nach Nummer (b1 ist der erste Kanal) oder nach Name, z. B. (b4 - b3) / (b4 + b3) oder 2.5 * (NIR - RED) / (NIR + 2.4 * RED + 1); Zahlen, + - * / ** und Klammern sowie die Funktionen sqrt, abs, log, exp, min, max, clip(x, low, high).
NIR-Kanalnummer, Rot-Kanalnummer, Red-Edge-Kanalnummer (erweitert): der Kanal, der für diesen Namen zu nehmen ist, wenn die Kanalnamen des Rasters ihn nicht oder falsch angeben; 0 liest ihn aus den Namen.
Indexraster: wohin das Float32-Cloud-Optimized-GeoTIFF geschrieben wird (NoData -9999, der Kanal mit dem Index und seiner Formel beschrieben).</translation>
    </message>
</context>
<context>
    <name>StackCapturesAlgorithm</name>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Band folder</source>
        <translation>Kanalordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Radiometry</source>
        <translation>Radiometrie</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Reference band</source>
        <translation>Referenzkanal</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="82"/>
        <source>Output folder</source>
        <translation>Ausgabeordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="83"/>
        <source>Photos written</source>
        <translation>Geschriebene Fotos</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="84"/>
        <source>Captures left out</source>
        <translation>Ausgelassene Aufnahmen</translation>
    </message>
    <message>
        <location filename="../ui/catalog.py" line="8"/>
        <source>Stack multispectral captures</source>
        <translation>Multispektrale Aufnahmen stapeln</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Calibration panel folder</source>
        <translation>Kalibrierpanel-Ordner</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Panel reflectance</source>
        <translation>Panelreflexion</translation>
    </message>
    <message>
        <location filename="../processing_provider/stack_captures.py" line="69"/>
        <source>Panel window</source>
        <translation>Panelfenster</translation>
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
        <translation>Macht aus den Kanaldateien einer Multispektralkamera (Parrot Sequoia, MicaSense RedEdge / Altum, DJI P4 Multispectral / Mavic 3M: ein 16-Bit-TIFF je Kanal und Aufnahme) ein mehrkanaliges Foto je Aufnahme, das Bilder ausrichten, Pipeline ausführen und Orthophoto erzeugen wie jedes Foto nehmen: das Orthomosaik hat dann jeden Kanal, und Spektralindex berechnet daraus NDVI oder NDRE. Die Dateien einer Aufnahme werden nach ihrer Aufnahme-ID gruppiert (sonst nach Rig-Name und Zeit); jeder Kanal wird mit seinem eigenen Objektivmodell aus seinen Metadaten entzerrt, um seine Rig-Rotation gedreht und durch Phasenkorrelation auf Gradienten auf den Referenzkanal registriert. Die Kanäle des Fotos beginnen mit NIR, Rot, Grün (QGIS zeigt sie als Falschfarbenansicht NIR-R-G), jeder mit seiner Wellenlänge benannt; das GPS der Aufnahme steht in seinem EXIF. Eine Aufnahme, der ein Kanal fehlt, wird ausgelassen und im Protokoll genannt; in den Kanalordner wird nie geschrieben.

Kanalordner: der Ordner der Kanaldateien (die Bilder der RGB-Kamera darin werden nicht gestapelt).
Radiometrie: normalisiert (Standard) zieht von jedem Kanal seinen Dunkelwert ab, korrigiert seine Vignettierung nach dem Modell der Datei und normalisiert Belichtungszeit und Verstärkung auf die des Blocks; Einstrahlung teilt zusätzlich durch die Einstrahlung des Sonnensensors für diesen Kanal (Werte proportional zur Reflexion, wenn sich das Licht während des Flugs ändert); roh behält die Werte wie aufgenommen. Eine Kanaldatei, der fehlt, was die Wahl braucht (eine Belichtungszeit, ein Sonnensensorwert), beendet den Lauf vor jeder Arbeit und nennt die Datei. Die Metadaten des Fotos sagen, was getan wurde (und je Kanal das Vignettierungsmodell, der Dunkelwert und der Maßstab).
Kalibrierpanel-Ordner (optional): die Kanaldateien der Aufnahmen des Kalibrierpanels (eine Aufnahme des Panels bekannter Reflexion in jedem Kanal, vor und / oder nach dem Flug, wie MicaSense, DJI und Parrot es verlangen), in einem eigenen Ordner. Damit enthalten die Fotos Reflexion (0..1, float32, 0 wo ein Kanal nicht hinreicht) statt 16-Bit-Werten: jeder Kanal wird mit der Reflexion des Panels geteilt durch den Wert des Panels nach derselben Radiometrie skaliert (normalisiert: das Panel legt jeden Kanal unter dem Licht seiner Aufnahme fest; Einstrahlung: der Sonnensensor folgt den Lichtänderungen während des Flugs); Panels vor und nach dem Flug werden gemittelt, und eine Warnung sagt, wenn sie um mehr als 3 % abweichen. Das Panel wird in der Mitte seines Fotos gemessen: eine Mitte, die gesättigt oder nicht gleichmäßig ist (kein Panel dort), beendet den Lauf vor jeder Arbeit und nennt die Datei; ebenso ein Panel einer anderen Kamera, eine Panelaufnahme, der ein Kanal fehlt, und eine Panelreflexion für einen Kanal, den das Rig nicht hat. Paneldateien, die unter den Kanaldateien liegen, werden nicht gestapelt.
Panelreflexion: die Reflexion des Panels laut seinem Kalibrierblatt: eine Zahl für jeden Kanal (0.5), je Kanal (Green=0.49,Red=0.50,Red edge=0.50,NIR=0.49) oder der Pfad einer CSV-Datei mit Zeilen Kanalname oder Wellenlänge in nm, Reflexion (eine Kurve von Wellenlängen wird an der Mitte jedes Kanals interpoliert). Nötig mit einem Kalibrierpanel-Ordner.
Panelfenster (erweitert): die Seite des mittleren Quadrats, in dem das Panel gemessen wird, als Anteil der kurzen Seite des Fotos (Standard 0.25); kleiner, wenn das Panel weniger vom Bild füllt.
Referenzkanal (erweitert): der Kanal, auf den die anderen registriert werden; leer: die Referenzkamera des Rigs.
Ausgabeordner: wohin die mehrkanaligen Fotos geschrieben werden (eines je Aufnahme, benannt nach ihren Kanaldateien ohne die Kanalendung); nicht der Kanalordner.</translation>
    </message>
</context>
</TS>
